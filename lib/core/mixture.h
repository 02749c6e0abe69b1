#pragma once
// A Gaussian mixture p(x) = sum_i w_i N(x; mu_i, S_i) / sum_i w_i with unnormalised weights
// (sample counts, eq. 3 of Edgington et al.).
#include <Eigen/Dense>
#include <random>
#include <vector>

#include "core/gaussian.h"

namespace dgmm {

// Options for the search of the mixture's maximum density.
struct ModeSearchOptions {
  int max_iterations = 200;
  double tolerance = 1e-10;  // stop when a fixed-point step moves less than this (L2).
};

class Mixture {
 public:
  Mixture() = default;
  explicit Mixture(int dim) : dim_(dim) {}

  int dim() const { return dim_; }
  int size() const { return static_cast<int>(components_.size()); }
  bool empty() const { return components_.empty(); }
  // Unnormalised weight w_i > 0 (a sample count for a DGMM).
  double weight(int i) const { return weights_[i]; }
  const std::vector<double>& weights() const { return weights_; }
  double total_weight() const;
  const Gaussian& component(int i) const { return components_[i]; }
  const std::vector<Gaussian>& components() const { return components_; }

  // Appends a component; weight must be > 0 and g.dim() == dim() (asserted).
  void Add(double weight, Gaussian g);
  void SetWeight(int i, double weight) { weights_[i] = weight; }
  void SetComponent(int i, Gaussian g) { components_[i] = std::move(g); }
  // In-place access for updates that must not reallocate (Dgmm::AddSample).
  Gaussian& mutable_component(int i) { return components_[i]; }

  // log p(x) by log-sum-exp over components.
  double LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // log p for each column of X (d x n).
  Eigen::VectorXd LogDensity(const Eigen::Ref<const Eigen::MatrixXd>& X) const;

  // Any Eigen vector or matrix expression: picks the single-point overload for a column
  // vector (compile-time one column) and the batch overload otherwise, so that calls with a
  // VectorXd, MatrixXd, .col(j), .tail(n) ... are never ambiguous.
  template <typename Derived>
  auto LogDensity(const Eigen::MatrixBase<Derived>& x) const {
    if constexpr (Derived::ColsAtCompileTime == 1) {
      return LogDensity(Eigen::Ref<const Eigen::VectorXd>(x));
    } else {
      return LogDensity(Eigen::Ref<const Eigen::MatrixXd>(x));
    }
  }
  // log(w_i N_i(x)) - log p(x) for each i: responsibilities in log space.
  Eigen::VectorXd LogResponsibilities(const Eigen::Ref<const Eigen::VectorXd>& x) const;

  // Marginal over the listed dimensions; weights unchanged.
  Mixture Marginal(const std::vector<int>& dims) const;
  // p(a | b = values) for a = the other dimensions (eqs. 15-19): each component conditioned
  // (Schur complement) and re-weighted by w_i N_i(values; marginal over b).
  Mixture Conditional(const std::vector<int>& given_dims,
                      const Eigen::Ref<const Eigen::VectorXd>& values) const;
  // Each component mapped by y = A x + b; weights unchanged.
  Mixture Affine(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) const;

  // n draws, returned as the columns of a d x n matrix.
  Eigen::MatrixXd Sample(int n, std::mt19937_64& rng) const;
  // One draw per column of `noise` (d x n, standard normal, e.g. correlated across calls):
  // x_j = mu_k + L_k noise_j with component k drawn by weight.
  Eigen::MatrixXd SampleWithNoise(const Eigen::Ref<const Eigen::MatrixXd>& noise, std::mt19937_64& rng) const;

  // argmax_x p(x) and log p there. Fixed-point mode search (Carreira-Perpinan 2000) started
  // from every component mean; the best local maximum found wins.
  struct Mode {
    Eigen::VectorXd x;
    double log_density = 0.0;
  };
  Mode MaxDensity(const ModeSearchOptions& options = {}) const;
  // The same fixed-point search from the given starting points only (O(starts x K) instead of
  // O(K^2)): the best local mode reached, a lower bound of the global one.
  Mode MaxDensityFrom(const std::vector<Eigen::VectorXd>& starts,
                      const ModeSearchOptions& options = {}) const;

 private:
  int dim_ = 0;
  std::vector<double> weights_;
  std::vector<Gaussian> components_;
};

}  // namespace dgmm
