#pragma once
// Options of one DGMM (Algorithm 2, ADDSAMPLE) and the names of their rules, as written in model
// files and on the command line (docs/dgmm.md, "Scale and covariance rules").
#include <Eigen/Dense>
#include <optional>
#include <string>

namespace dgmm {

struct DgmmOptions {
  // Which ADDSAMPLE: the paper's (default) or the improved single-pass variant (docs/dgmm.md).
  enum class Variant { kFaithful, kImproved };
  Variant variant = Variant::kFaithful;
  // Merge rate k > 0 in t = 1 - (1 - d) exp(-k n).
  double k = 0.7;

  // Covariance of a component from its count n, scatter M2 and S0 = diag(initial diagonal):
  //   kLiteral: M2 / (n - 1) (eq. 13; S0 for n = 1),
  //   kBlend:   (M2 + nu S0) / (n - 1 + nu), nu = max(0, d + 1 - n) (version-1 behaviour),
  //   kPrior:   (M2 + nu0 S0) / (n + nu0), the Normal-inverse-Wishart posterior mean of Sigma
  //             with pseudo-count nu0 = prior_pseudo_count (flat prior on the mean);
  // each plus covariance_floor * I.
  enum class CovarianceRule { kLiteral, kBlend, kPrior };
  CovarianceRule covariance_rule = CovarianceRule::kPrior;
  double prior_pseudo_count = 4.0;  // nu0 > 0 for kPrior (ignored otherwise)

  // Where S0 comes from: kIdentity (the paper's, S0 = I in the data's units), kData
  // (S0 = initial_covariance_fraction * v, v the pooled within-command per-dimension variance of
  // the training set, core/data_scale.h) or kUser (initial_covariance_diagonal as given).
  enum class InitialCovarianceRule { kIdentity, kData, kUser };
  InitialCovarianceRule initial_covariance_rule = InitialCovarianceRule::kData;
  double initial_covariance_fraction = 0.3;  // for kData (default chosen in docs/dgmm.md)
  // S0's diagonal. Empty until resolved (ResolveDgmmOptions) unless kUser; a Dgmm needs it
  // resolved for kData, and takes ones for an empty diagonal under kIdentity.
  Eigen::VectorXd initial_covariance_diagonal;

  // Absolute floor added to every covariance's diagonal. When covariance_floor_relative > 0,
  // ResolveDgmmOptions sets covariance_floor = covariance_floor_relative * min_j v_j.
  double covariance_floor = 1e-6;
  double covariance_floor_relative = 1e-6;
  // At most this many components (0: no cap). At the cap every sample merges (the component is
  // chosen as usual) and max_components_hit() turns true (issue #13: bounded work).
  int max_components = 0;

  // k finite and > 0, floor finite and >= 0, relative floor finite and >= 0, fraction finite
  // and > 0, nu0 finite and > 0 for kPrior, initial diagonal (if given) positive and finite.
  bool IsValid(std::string* error) const;
  // As above, the initial diagonal (if given) has `dim` entries, and for kData it is resolved.
  bool IsValid(int dim, std::string* error) const;
  // S0's diagonal for `dim` dimensions: the stored one, or ones when empty (kIdentity).
  Eigen::VectorXd ResolvedInitialDiagonal(int dim) const;
};

// Default cap on components per mixture for `samples` samples of `dim` dimensions
// (docs/reliability.md, "Bounded work"): the square-root rule ceil(sqrt(N)); at most N / (d + 1)
// (a component's covariance needs d + 1 samples); at most 2e9 / (N d^2), since each sample costs
// about K d^2 once the cap is reached; never below 50 so that small sets are not capped.
long long DefaultMaxComponents(long long samples, int dim);

// Names as in model files and flags: "faithful"/"improved", "literal"/"blend"/"prior",
// "identity"/"data"/"user".
const char* VariantName(DgmmOptions::Variant v);
const char* CovarianceRuleName(DgmmOptions::CovarianceRule r);
const char* InitialCovarianceRuleName(DgmmOptions::InitialCovarianceRule r);
std::optional<DgmmOptions::Variant> ParseVariant(const std::string& name);
std::optional<DgmmOptions::CovarianceRule> ParseCovarianceRule(const std::string& name);
std::optional<DgmmOptions::InitialCovarianceRule> ParseInitialCovarianceRule(
    const std::string& name);

}  // namespace dgmm
