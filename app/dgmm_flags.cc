#include "app/dgmm_flags.h"

#include <fmt/format.h>

#include <cmath>

#include "util/error.h"

namespace dgmm::app {

void AddDgmmFlags(CLI::App* cmd, DgmmFlags* f) {
  cmd->add_option("--variant", f->variant, "faithful (the paper's Algorithm 2) or improved")
      ->capture_default_str();
  cmd->add_option("--covariance", f->covariance,
                  "component covariance rule: literal (eq. 13, M2/(n-1)), blend "
                  "((M2 + nu S0)/(n-1+nu), nu = max(0, d+1-n)) or prior ((M2 + nu0 S0)/(n + nu0))")
      ->capture_default_str();
  cmd->add_option("--prior-count", f->prior_count, "nu0 of the prior rule, > 0")
      ->capture_default_str();
  cmd->add_option("--init-cov", f->init_cov,
                  "initial covariance S0 of a new component: 'data' (--init-scale times the "
                  "pooled within-command variance), 'identity' (the paper's) or one value for "
                  "every dimension or one per dimension, comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--init-scale", f->init_scale,
                  "fraction of the pooled within-command variance used by --init-cov data")
      ->capture_default_str();
  f->floor_option =
      cmd->add_option("--floor", f->floor,
                      "absolute covariance floor (default: --floor-relative times the smallest "
                      "pooled within-command variance)");
  cmd->add_option("--floor-relative", f->floor_relative,
                  "covariance floor as a fraction of the smallest pooled within-command variance")
      ->capture_default_str();
}

DgmmOptions DgmmOptionsFromFlags(const DgmmFlags& f, int dim) {
  DgmmOptions o;
  if (auto v = ParseVariant(f.variant)) {
    o.variant = *v;
  } else {
    throw MakeInputError("", "--variant", "'" + f.variant + "', expected faithful or improved");
  }
  if (auto r = ParseCovarianceRule(f.covariance)) {
    o.covariance_rule = *r;
  } else {
    throw MakeInputError("", "--covariance",
                         "'" + f.covariance + "', expected literal, blend or prior");
  }
  if (!(f.prior_count > 0) || !std::isfinite(f.prior_count)) {
    throw MakeInputError("", "--prior-count", fmt::format("must be > 0, got {}", f.prior_count));
  }
  o.prior_pseudo_count = f.prior_count;
  if (!(f.init_scale > 0) || !std::isfinite(f.init_scale)) {
    throw MakeInputError("", "--init-scale", fmt::format("must be > 0, got {}", f.init_scale));
  }
  o.initial_covariance_fraction = f.init_scale;
  if (f.init_cov.size() == 1 && f.init_cov[0] == "identity") {
    o.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;
  } else if (f.init_cov.empty() || (f.init_cov.size() == 1 && f.init_cov[0] == "data")) {
    o.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kData;
  } else {
    std::vector<double> values;
    for (const std::string& s : f.init_cov) {
      std::size_t used = 0;
      double v = 0;
      try {
        v = std::stod(s, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != s.size() || !std::isfinite(v) || !(v > 0)) {
        throw MakeInputError("", "--init-cov",
                             "'" + s + "', expected identity, data or numbers > 0");
      }
      values.push_back(v);
    }
    if (values.size() != 1 && static_cast<int>(values.size()) != dim) {
      throw MakeInputError(
          "", "--init-cov",
          fmt::format("{} values for {} dimensions (give 1 or {})", values.size(), dim, dim));
    }
    o.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kUser;
    o.initial_covariance_diagonal =
        values.size() == 1 ? Eigen::VectorXd::Constant(dim, values[0])
                           : Eigen::Map<const Eigen::VectorXd>(values.data(), dim).eval();
  }
  if (f.floor_option != nullptr && f.floor_option->count() > 0) {
    if (!(f.floor >= 0) || !std::isfinite(f.floor)) {
      throw MakeInputError("", "--floor", "must be finite and >= 0");
    }
    o.covariance_floor = f.floor;
    o.covariance_floor_relative = 0;
  } else {
    if (!(f.floor_relative >= 0) || !std::isfinite(f.floor_relative)) {
      throw MakeInputError("", "--floor-relative", "must be finite and >= 0");
    }
    o.covariance_floor_relative = f.floor_relative;
  }
  return o;
}

std::vector<std::string> NonDefaultDgmmFlags(const DgmmFlags& f) {
  const DgmmFlags defaults;
  std::vector<std::string> words;
  if (f.variant != defaults.variant) words.insert(words.end(), {"--variant", f.variant});
  if (f.covariance != defaults.covariance)
    words.insert(words.end(), {"--covariance", f.covariance});
  if (f.init_cov != defaults.init_cov) {
    std::string joined;
    for (const auto& v : f.init_cov) joined += (joined.empty() ? "" : ",") + v;
    words.insert(words.end(), {"--init-cov", joined});
  }
  if (f.floor_option != nullptr && f.floor_option->count() > 0) {
    words.insert(words.end(), {"--floor", fmt::format("{:.6g}", f.floor)});
  } else if (f.floor_relative != defaults.floor_relative) {
    words.insert(words.end(), {"--floor-relative", fmt::format("{:.6g}", f.floor_relative)});
  }
  return words;
}

}  // namespace dgmm::app
