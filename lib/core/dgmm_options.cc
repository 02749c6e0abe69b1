#include "core/dgmm_options.h"

#include <algorithm>
#include <cmath>

namespace dgmm {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

bool FinitePositive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

bool DgmmOptions::IsValid(std::string* error) const {
  if (!FinitePositive(k)) {
    return Fail(error, "k must be a finite number > 0, got " + std::to_string(k));
  }
  if (!std::isfinite(covariance_floor) || covariance_floor < 0) {
    return Fail(
        error, "covariance floor must be finite and >= 0, got " + std::to_string(covariance_floor));
  }
  if (!std::isfinite(covariance_floor_relative) || covariance_floor_relative < 0) {
    return Fail(error, "relative covariance floor must be finite and >= 0, got " +
                           std::to_string(covariance_floor_relative));
  }
  if (max_components < 0) {
    return Fail(error, "max components must be >= 0 (0: no cap), got " +
                           std::to_string(max_components));
  }
  if (!FinitePositive(initial_covariance_fraction)) {
    return Fail(error, "initial covariance fraction must be finite and > 0, got " +
                           std::to_string(initial_covariance_fraction));
  }
  if (covariance_rule == CovarianceRule::kPrior && !FinitePositive(prior_pseudo_count)) {
    return Fail(error, "prior pseudo-count must be finite and > 0, got " +
                           std::to_string(prior_pseudo_count));
  }
  for (int i = 0; i < initial_covariance_diagonal.size(); ++i) {
    const double v = initial_covariance_diagonal[i];
    if (!FinitePositive(v)) {
      return Fail(error, "initial covariance diagonal entry " + std::to_string(i) +
                             " must be finite and > 0, got " + std::to_string(v));
    }
  }
  return true;
}

bool DgmmOptions::IsValid(int dim, std::string* error) const {
  if (!IsValid(error)) return false;
  if (initial_covariance_diagonal.size() != 0 && initial_covariance_diagonal.size() != dim) {
    return Fail(error, "initial covariance diagonal has " +
                           std::to_string(initial_covariance_diagonal.size()) +
                           " entries, the model has " + std::to_string(dim) + " dimensions");
  }
  if (initial_covariance_diagonal.size() == 0 &&
      initial_covariance_rule != InitialCovarianceRule::kIdentity) {
    return Fail(error, std::string("initial covariance rule '") +
                           InitialCovarianceRuleName(initial_covariance_rule) +
                           "' needs a resolved diagonal (ResolveDgmmOptions)");
  }
  return true;
}

Eigen::VectorXd DgmmOptions::ResolvedInitialDiagonal(int dim) const {
  if (initial_covariance_diagonal.size() == dim) return initial_covariance_diagonal;
  return Eigen::VectorXd::Ones(dim);
}

const char* VariantName(DgmmOptions::Variant v) {
  return v == DgmmOptions::Variant::kImproved ? "improved" : "faithful";
}

const char* CovarianceRuleName(DgmmOptions::CovarianceRule r) {
  switch (r) {
    case DgmmOptions::CovarianceRule::kLiteral:
      return "literal";
    case DgmmOptions::CovarianceRule::kBlend:
      return "blend";
    case DgmmOptions::CovarianceRule::kPrior:
      return "prior";
  }
  return "?";
}

const char* InitialCovarianceRuleName(DgmmOptions::InitialCovarianceRule r) {
  switch (r) {
    case DgmmOptions::InitialCovarianceRule::kIdentity:
      return "identity";
    case DgmmOptions::InitialCovarianceRule::kData:
      return "data";
    case DgmmOptions::InitialCovarianceRule::kUser:
      return "user";
  }
  return "?";
}

std::optional<DgmmOptions::Variant> ParseVariant(const std::string& name) {
  if (name == "faithful") return DgmmOptions::Variant::kFaithful;
  if (name == "improved") return DgmmOptions::Variant::kImproved;
  return std::nullopt;
}

std::optional<DgmmOptions::CovarianceRule> ParseCovarianceRule(const std::string& name) {
  if (name == "literal") return DgmmOptions::CovarianceRule::kLiteral;
  if (name == "blend") return DgmmOptions::CovarianceRule::kBlend;
  if (name == "prior") return DgmmOptions::CovarianceRule::kPrior;
  return std::nullopt;
}

std::optional<DgmmOptions::InitialCovarianceRule> ParseInitialCovarianceRule(
    const std::string& name) {
  if (name == "identity") return DgmmOptions::InitialCovarianceRule::kIdentity;
  if (name == "data") return DgmmOptions::InitialCovarianceRule::kData;
  if (name == "user") return DgmmOptions::InitialCovarianceRule::kUser;
  return std::nullopt;
}

long long DefaultMaxComponents(long long n, int dim) {
  constexpr double kWorkBudget = 2e9;  // N K d^2 multiply-adds: a few seconds of one core
  const double nd = static_cast<double>(n), d = dim;
  const double cap = std::min({std::ceil(std::sqrt(nd)), std::floor(nd / (d + 1)),
                               std::floor(kWorkBudget / (std::max(nd, 1.0) * d * d))});
  return std::max<long long>(50, static_cast<long long>(cap));
}

}  // namespace dgmm
