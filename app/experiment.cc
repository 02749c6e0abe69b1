// `dgmm experiment old-faithful`: the protocol of section VI-A of Edgington et al. (2009) on a
// standardised 2-D sample set, written as CSV/JSON/model files for
// scripts/reproduce_old_faithful.sh (documented in docs/reproduction.md; hidden from --help).
//  - k sweep (Figure 2): Gaussians after one pass over the shuffled data, many seeds per k.
//  - MISE: shuffle and fit with k until `runs` fits end with exactly `target` Gaussians; the
//    closed-form ISE of each against the EM model, plus diagnostics of why it is what it is.
//  - Held-out log-likelihood: K-fold cross-validation of EM and DGMM side by side.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>

#include "app/command.h"
#include "core/data_scale.h"
#include "core/dgmm.h"
#include "core/mise.h"
#include "core/motion_model.h"
#include "em/em.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct ExperimentArgs {
  std::string set, em, out_dir;
  std::vector<std::string> variants{"faithful", "improved"};
  double k = 0.7;
  int grid_points = 19, seeds_per_k = 50, runs = 100, target = 2, max_attempts = 20000;
  int folds = 10, cv_seeds = 10;
  std::uint64_t seed = 1;
  std::string init_cov = "identity";                      // S0: identity (the paper's) or data
  double prior_count = DgmmOptions{}.prior_pseudo_count;  // nu0 of the prior rule
  bool json = false;
};

// One shuffled single pass: the mixture, which component each sample went to (in data-row
// order), and the sample count at which the last new component was started.
struct Pass {
  Mixture mixture;
  std::vector<int> component_of_row;
  int last_new_component_at = 0;
};

// "<faithful|improved>[-<literal|blend|prior>]" (the rule defaults to the library's) with S0
// from a.init_cov, resolved against y's per-dimension variance (one command: pooled = total).
// Throws InputError for an unknown name.
DgmmOptions OptionsFor(const std::string& variant, double k, const ExperimentArgs& a,
                       const Eigen::MatrixXd& y) {
  DgmmOptions o;
  o.k = k;
  const std::size_t dash = variant.find('-');
  const auto v = ParseVariant(variant.substr(0, dash));
  const auto rule = dash == std::string::npos ? std::optional(o.covariance_rule)
                                              : ParseCovarianceRule(variant.substr(dash + 1));
  if (!v || !rule) {
    throw MakeInputError("", "--variants",
                         "'" + variant +
                             "', expected faithful or improved, optionally followed "
                             "by -literal, -blend or -prior");
  }
  o.variant = *v;
  o.covariance_rule = *rule;
  o.prior_pseudo_count = a.prior_count;
  const auto init = ParseInitialCovarianceRule(a.init_cov);
  if (!init || *init == DgmmOptions::InitialCovarianceRule::kUser) {
    throw MakeInputError("", "--init-cov", "'" + a.init_cov + "', expected identity or data");
  }
  o.initial_covariance_rule = *init;
  DataScaleAccumulator scale(static_cast<int>(y.cols()));
  for (Eigen::Index i = 0; i < y.rows(); ++i) scale.Add(0, y.row(i).transpose());
  return ResolveDgmmOptions(o, scale.PooledVariance());
}

Pass ShuffledPass(const Eigen::MatrixXd& y, const std::vector<int>& rows, const DgmmOptions& o,
                  std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<int> order = rows;
  std::shuffle(order.begin(), order.end(), rng);
  Dgmm model(static_cast<int>(y.cols()), o);
  Pass pass;
  pass.component_of_row.assign(y.rows(), -1);
  for (size_t i = 0; i < order.size(); ++i) {
    Eigen::VectorXd x = y.row(order[i]).transpose();
    AddSampleResult r = model.AddSample(x, rng);
    pass.component_of_row[order[i]] = r.component;
    if (!r.merged) pass.last_new_component_at = static_cast<int>(i) + 1;
  }
  pass.mixture = model.mixture();
  return pass;
}

// Fraction of samples whose DGMM component disagrees with the EM cluster (most responsible EM
// component), under the best matching of the two labelings (2 components only; else NaN).
double Impurity(const Pass& pass, const Mixture& em, const Eigen::MatrixXd& y) {
  if (pass.mixture.size() != 2 || em.size() != 2) return NAN;
  int agree = 0;
  for (Eigen::Index i = 0; i < y.rows(); ++i) {
    Eigen::VectorXd r = em.LogResponsibilities(y.row(i).transpose());
    agree += (r(0) >= r(1) ? 0 : 1) == pass.component_of_row[i];
  }
  const double n = static_cast<double>(y.rows());
  return std::min(agree, static_cast<int>(y.rows()) - agree) / n;
}

double Mean(const std::vector<double>& v) {
  return v.empty() ? NAN : std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}
double Sd(const std::vector<double>& v) {
  if (v.size() < 2) return NAN;
  const double m = Mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}
double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  AtomicFile file(path);
  std::ofstream(file.temp_path()) << text;
  file.Commit();
}

// Mean log-likelihood per sample in raw units: log p_std(y) - sum log scale.
double MeanHeldOutLogLikelihood(const Mixture& m, const Eigen::MatrixXd& y,
                                const std::vector<int>& rows, double log_jacobian) {
  double total = 0;
  for (int r : rows) total += m.LogDensity(Eigen::VectorXd(y.row(r).transpose()));
  return total / rows.size() - log_jacobian;
}

nlohmann::json RunVariant(const ExperimentArgs& a, const std::string& variant,
                          const Eigen::MatrixXd& y, const MotionModel& em_model,
                          const MotionModel& header, double log_jacobian) {
  namespace fs = std::filesystem;
  const Mixture& em = em_model.mixtures.begin()->second;
  std::vector<int> all(y.rows());
  std::iota(all.begin(), all.end(), 0);
  nlohmann::json out;

  // Figure 2: number of Gaussians against k on a log grid 0.01 .. 10.
  std::string sweep = "k,mean,sd,q10,median,q90,fraction_target\n";
  for (int g = 0; g < a.grid_points; ++g) {
    const double k = std::pow(10.0, -2.0 + 3.0 * g / std::max(1, a.grid_points - 1));
    std::vector<double> counts;
    for (int s = 0; s < a.seeds_per_k; ++s) {
      counts.push_back(
          ShuffledPass(y, all, OptionsFor(variant, k, a, y), a.seed * 100003 + s).mixture.size());
      ReportProgress(variant + " k sweep", g * a.seeds_per_k + s + 1,
                     static_cast<long long>(a.grid_points) * a.seeds_per_k);
    }
    double frac = std::count(counts.begin(), counts.end(), a.target) / double(counts.size());
    sweep += fmt::format("{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", k, Mean(counts),
                         Sd(counts), Quantile(counts, 0.1), Quantile(counts, 0.5),
                         Quantile(counts, 0.9), frac);
  }
  WriteText(fs::path(a.out_dir) / (variant + "_k_sweep.csv"), sweep);

  // MISE: fits at k until `runs` end with exactly `target` Gaussians.
  std::vector<double> ise, ise_raw, impurity, frozen_at;
  std::vector<std::pair<double, std::uint64_t>> by_ise;
  std::vector<double> all_counts;
  const double jacobian = std::exp(log_jacobian);
  std::string runs_csv = "run,seed,components,ise_standardised,ise_raw,impurity,last_new_at\n";
  int attempts = 0;
  for (; attempts < a.max_attempts && static_cast<int>(ise.size()) < a.runs; ++attempts) {
    const std::uint64_t seed = a.seed * 7919 + attempts;
    Pass pass = ShuffledPass(y, all, OptionsFor(variant, a.k, a, y), seed);
    all_counts.push_back(pass.mixture.size());
    if (pass.mixture.size() != a.target) continue;
    const double v = IntegratedSquaredError(pass.mixture, em);
    ise.push_back(v);
    ise_raw.push_back(v / jacobian);
    impurity.push_back(Impurity(pass, em, y));
    frozen_at.push_back(pass.last_new_component_at);
    by_ise.emplace_back(v, seed);
    runs_csv +=
        fmt::format("{},{},{},{:.6g},{:.6g},{:.6g},{}\n", ise.size(), seed, pass.mixture.size(), v,
                    v / jacobian, impurity.back(), pass.last_new_component_at);
    ReportProgress(variant + " MISE runs", static_cast<long long>(ise.size()), a.runs);
  }
  WriteText(fs::path(a.out_dir) / (variant + "_mise_runs.csv"), runs_csv);
  // How all fits at k ended: number of Gaussians -> number of fits (with --runs above
  // --max-attempts this is a fixed number of shuffles, free of the stop-at-`runs` rule).
  std::map<int, int> histogram;
  for (double c : all_counts) ++histogram[static_cast<int>(c)];
  nlohmann::json components_histogram = nlohmann::json::array();
  for (const auto& [components, fits] : histogram) components_histogram.push_back({components, fits});
  out["mise"] = {{"k", a.k},
                 {"target_components", a.target},
                 {"runs", ise.size()},
                 {"attempts", attempts},
                 {"fraction_with_target", ise.size() / double(std::max(1, attempts))},
                 {"mean_components_all_attempts", Mean(all_counts)},
                 {"components_histogram", components_histogram},
                 {"mean", Mean(ise)},
                 {"sd", Sd(ise)},
                 {"median", Quantile(ise, 0.5)},
                 {"mean_raw_units", Mean(ise_raw)},
                 {"sd_raw_units", Sd(ise_raw)},
                 {"mean_impurity", Mean(impurity)},
                 {"mean_last_new_component_at", Mean(frozen_at)}};
  // The run with the median ISE is the representative model of Figure 3.
  if (!by_ise.empty()) {
    std::sort(by_ise.begin(), by_ise.end());
    const std::uint64_t seed = by_ise[by_ise.size() / 2].second;
    MotionModel model = header;
    model.kind = "dgmm";
    model.dgmm_options = OptionsFor(variant, a.k, a, y);
    model.seed = seed;
    model.mixtures.clear();
    model.mixtures[em_model.mixtures.begin()->first] =
        ShuffledPass(y, all, OptionsFor(variant, a.k, a, y), seed).mixture;
    model.metadata["experiment"] =
        "old-faithful median-ISE run, shuffled order seed " + std::to_string(seed);
    const std::string path = (fs::path(a.out_dir) / (variant + "_dgmm_median.h5")).string();
    WriteModel(model, path);
    out["median_model"] = path;
    out["median_model_ise"] = by_ise[by_ise.size() / 2].first;
  }
  return out;
}

void Run(const ExperimentArgs& a) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(a.out_dir)) throw MakeInputError(a.out_dir, "", "not a directory");
  if (!(a.k > 0) || !(a.prior_count > 0) || a.runs < 1 || a.folds < 2 || a.grid_points < 2 ||
      a.seeds_per_k < 1 || a.cv_seeds < 1 || a.target < 1) {
    throw MakeInputError("", "options",
                         "k > 0, prior count > 0, runs >= 1, folds >= 2, grid >= 2 needed");
  }
  const SampleSet set = ReadSampleSet(a.set);
  const MotionModel em_model = ReadModel(a.em);
  if (set.num_commands() != 1 || set.terrain_dim() != 0 || em_model.mixtures.size() != 1 ||
      em_model.dim() != set.pose_dim()) {
    throw MakeInputError(a.set, "", "expects one command, no terrain, and an EM model of it");
  }
  const Eigen::MatrixXd& y = set.x;
  for (const auto& v : a.variants) OptionsFor(v, a.k, a, y);  // unknown names fail here
  const double log_jacobian =
      set.transform.empty() ? 0.0 : set.transform.scale.array().abs().log().sum();
  MotionModelOptions header_options;
  header_options.dgmm = OptionsFor(a.variants.front(), a.k, a, y);
  const MotionModel header = LearnMotionModel(set.Subset({0}), header_options);

  nlohmann::json report = {{"set", a.set},
                           {"em", a.em},
                           {"samples", set.size()},
                           {"standardised", !set.transform.empty()},
                           {"em_components", em_model.mixtures.begin()->second.size()}};
  for (const auto& v : a.variants) report[v] = RunVariant(a, v, y, em_model, header, log_jacobian);

  // Held-out log-likelihood, K-fold: EM (same options as the model file) and DGMM (k, averaged
  // over cv_seeds shuffles) trained on K-1 folds, scored on the held-out fold, raw units.
  std::mt19937_64 rng(a.seed);
  std::vector<int> perm(set.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::string cv = "fold,em";
  for (const auto& v : a.variants) cv += "," + v;
  cv += "\n";
  std::map<std::string, std::vector<double>> scores;
  for (int f = 0; f < a.folds; ++f) {
    std::vector<int> train, test;
    for (int i = 0; i < set.size(); ++i) (i % a.folds == f ? test : train).push_back(perm[i]);
    Eigen::MatrixXd y_train(train.size(), y.cols());
    for (size_t i = 0; i < train.size(); ++i) y_train.row(i) = y.row(train[i]);
    EmOptions em_options;
    em_options.components = em_model.mixtures.begin()->second.size();
    em_options.n_init = 10;
    em_options.seed = a.seed + f;
    const double em_ll =
        MeanHeldOutLogLikelihood(FitEm(y_train, em_options).mixture, y, test, log_jacobian);
    scores["em"].push_back(em_ll);
    cv += fmt::format("{},{:.6g}", f, em_ll);
    for (const auto& v : a.variants) {
      std::vector<double> lls;
      for (int s = 0; s < a.cv_seeds; ++s) {
        Pass pass = ShuffledPass(y, train, OptionsFor(v, a.k, a, y), a.seed * 31 + f * 1000 + s);
        lls.push_back(MeanHeldOutLogLikelihood(pass.mixture, y, test, log_jacobian));
      }
      scores[v].push_back(Mean(lls));
      cv += fmt::format(",{:.6g}", Mean(lls));
    }
    cv += "\n";
    ReportProgress("cross-validation folds", f + 1, a.folds);
  }
  WriteText(fs::path(a.out_dir) / "cv.csv", cv);
  std::string cv_summary = "method,mean,sd\n";
  for (const auto& [name, v] : scores) {
    report["cv"][name] = {{"mean", Mean(v)}, {"sd", Sd(v)}, {"folds", v.size()}};
    cv_summary += fmt::format("{},{:.6g},{:.6g}\n", name, Mean(v), Sd(v));
  }
  WriteText(fs::path(a.out_dir) / "cv_summary.csv", cv_summary);
  WriteText(fs::path(a.out_dir) / "summary.json", report.dump(2) + "\n");
  if (a.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    for (const auto& v : a.variants) {
      std::cout << fmt::format("{}: ISE vs EM over {} runs with {} Gaussians: {:.4g} +- {:.4g}\n",
                               v, report[v]["mise"]["runs"].get<int>(), a.target,
                               report[v]["mise"]["mean"].get<double>(),
                               report[v]["mise"]["sd"].get<double>());
    }
    std::cout << "wrote " << a.out_dir << "/summary.json\n";
  }
}

void Setup(CLI::App& root) {
  auto a = std::make_shared<ExperimentArgs>();
  CLI::App* experiment = root.add_subcommand("experiment", "Paper reproductions (for scripts)");
  experiment->group("");  // hidden: used by scripts/reproduce_old_faithful.sh
  experiment->require_subcommand(1);
  CLI::App* cmd = experiment->add_subcommand(
      "old-faithful", "Section VI-A protocol: k sweep, MISE against EM, cross-validation");
  cmd->add_option("set", a->set, "standardised sample set (one command, 2-D)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--em", a->em, "EM model of the set (dgmm em)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out-dir", a->out_dir, "folder for CSV, JSON and model files")->required();
  cmd->add_option("--variants", a->variants, "faithful,improved[-literal|-blend|-prior],...")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--k", a->k, "merge rate of the MISE runs and CV")->capture_default_str();
  cmd->add_option("--grid-points", a->grid_points, "k values, log grid 0.01..10")
      ->capture_default_str();
  cmd->add_option("--seeds-per-k", a->seeds_per_k, "shuffles per k")->capture_default_str();
  cmd->add_option("--runs", a->runs, "runs with --target Gaussians for the MISE")
      ->capture_default_str();
  cmd->add_option("--target", a->target, "number of Gaussians a run must end with")
      ->capture_default_str();
  cmd->add_option("--max-attempts", a->max_attempts, "stop after this many fits")
      ->capture_default_str();
  cmd->add_option("--folds", a->folds, "cross-validation folds")->capture_default_str();
  cmd->add_option("--cv-seeds", a->cv_seeds, "DGMM shuffles per fold")->capture_default_str();
  cmd->add_option("--seed", a->seed, "base seed")->capture_default_str();
  cmd->add_option("--init-cov", a->init_cov, "S0: identity (the paper's) or data")
      ->capture_default_str();
  cmd->add_option("--prior-count", a->prior_count, "nu0 of the prior rule (> 0)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "print the summary as JSON");
  cmd->callback([a] { Run(*a); });
}

}  // namespace

DGMM_REGISTER_COMMAND("experiment", Setup);

}  // namespace dgmm::app
