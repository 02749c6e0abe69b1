#pragma once
// Dynamic Gaussian Mixture Model (Edgington, Kassahun & Kirchner, Algorithm 2 ADDSAMPLE):
// samples arrive one at a time and either merge into a component or start a new one, decided by
// t = 1 - (1 - d) exp(-k n), d = p(x) / max p. No sample history is kept.
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/mixture.h"

namespace dgmm {

struct DgmmOptions {
  // Which ADDSAMPLE: the paper's (default) or the improved single-pass variant (docs/dgmm.md).
  enum class Variant { kFaithful, kImproved };
  Variant variant = Variant::kFaithful;
  // Merge rate k > 0 in t = 1 - (1 - d) exp(-k n).
  double k = 0.7;
  // Diagonal of a new component's covariance; empty means the identity (the paper's choice).
  Eigen::VectorXd initial_covariance_diagonal;
  // Floor added to keep covariances positive definite (see docs/dgmm.md for where it applies).
  double covariance_floor = 1e-6;

  bool IsValid(std::string* error) const;
};

// Sufficient statistics of one component: n samples, their mean and scatter
// M2 = sum (x - mean)(x - mean)^T; nothing else about the samples is kept.
struct DgmmComponentStats {
  std::int64_t count = 0;
  Eigen::VectorXd mean;
  Eigen::MatrixXd scatter;
};

// What ADDSAMPLE did with one sample.
struct AddSampleResult {
  bool merged = false;   // false: a new component was started.
  int component = -1;    // index of the component that received the sample.
  double threshold = 0;  // t
};

class Dgmm {
 public:
  // dim-dimensional model; options must be valid (asserted).
  Dgmm(int dim, DgmmOptions options);

  int dim() const { return dim_; }
  const DgmmOptions& options() const { return options_; }
  // n: samples added so far.
  std::int64_t num_samples() const { return num_samples_; }
  // The current model: weights are sample counts, covariances the floored per-component ones.
  const Mixture& mixture() const { return mixture_; }
  const std::vector<DgmmComponentStats>& stats() const { return stats_; }
  // Unbiased sample covariance M2 / (n - 1) of component i (before any floor); n >= 2.
  Eigen::MatrixXd SampleCovariance(int i) const;

  // ADDSAMPLE (Algorithm 2) for x (dim entries, finite: asserted).
  AddSampleResult AddSample(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng);

 private:
  int dim_;
  DgmmOptions options_;
  std::int64_t num_samples_ = 0;
  Mixture mixture_;
  std::vector<DgmmComponentStats> stats_;
};

}  // namespace dgmm
