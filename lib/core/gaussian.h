#pragma once
// A multivariate normal N(mean, covariance) with its Cholesky factor cached.
#include <Eigen/Dense>
#include <atomic>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

namespace dgmm {

class Gaussian {
 public:
  Gaussian() = default;
  Gaussian(const Gaussian& other);
  Gaussian(Gaussian&& other) noexcept;
  Gaussian& operator=(const Gaussian& other);
  Gaussian& operator=(Gaussian&& other) noexcept;
  // N(mean, covariance); covariance d x d must be symmetric positive definite (asserted).
  Gaussian(Eigen::VectorXd mean, Eigen::MatrixXd covariance);
  // Like the constructor but returns nullopt when the covariance does not factor.
  static std::optional<Gaussian> Create(Eigen::VectorXd mean, Eigen::MatrixXd covariance);

  int dim() const { return static_cast<int>(mean_.size()); }
  const Eigen::VectorXd& mean() const { return mean_; }
  // After rank-one updates the matrix is rebuilt from the factor (L L^T, exactly symmetric) on
  // the first read, so that the updates cost no d x d rewrite; safe to call from many threads.
  const Eigen::MatrixXd& covariance() const {
    if (covariance_stale_.load(std::memory_order_acquire)) RestoreCovariance();
    return covariance_;
  }
  // Lower factor L with covariance = L L^T.
  const Eigen::MatrixXd& cholesky_l() const { return l_; }
  // log det(covariance) = 2 sum log L_ii (kept as log_det_ + log det_factor_: rank-one updates
  // multiply their determinant ratio into det_factor_ and take no logarithm).
  double log_det() const { return det_factor_ == 1.0 ? log_det_ : log_det_ + std::log(det_factor_); }

  // Replaces mean and covariance and refactors; returns false (and keeps the old state) if the
  // covariance is not positive definite.
  bool Set(Eigen::VectorXd mean, Eigen::MatrixXd covariance);
  // Same as Set, reusing this object's storage (no heap allocation once sizes are stable);
  // used by the DGMM update on every merged sample.
  bool SetInPlace(const Eigen::Ref<const Eigen::VectorXd>& mean,
                  const Eigen::Ref<const Eigen::MatrixXd>& covariance);
  // covariance <- alpha covariance + rho v v^T (alpha > 0, rho >= 0) and the mean replaced, in
  // O(d^2): the cached factor gets a rank-one update (L' L'^T = alpha L L^T + rho v v^T) instead of
  // a new factorisation, and covariance() follows from it when next read. l_inv_v: L^-1 v
  // (dim() values) when the caller has it (WhitenEach gives L^-1 (x - mean)), else computed here.
  // Returns false (state unchanged) when the result would not be finite.
  bool ScaleAndRankOneUpdate(const Eigen::Ref<const Eigen::VectorXd>& mean, double alpha,
                             const Eigen::Ref<const Eigen::VectorXd>& v, double rho = 1.0,
                             const double* l_inv_v = nullptr);

  // m^2 = (x - mean)^T covariance^-1 (x - mean); x has dim() entries.
  double SquaredMahalanobis(const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // For each Gaussian i (all of x's dimension): z_i = L_i^-1 (x - mean_i) into z + i d and
  // m2[i] = |z_i|^2 = SquaredMahalanobis(x), two Gaussians at a time so that their forward
  // substitutions (latency-bound dependency chains) overlap.
  static void WhitenEach(const std::vector<Gaussian>& gaussians,
                         const Eigen::Ref<const Eigen::VectorXd>& x, double* z, double* m2);
  // log N(x; mean, covariance) = -1/2 (d log 2 pi + log det + m^2).
  double LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // log N for each column of X (d x n); returns n values.
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
  // The density scaled so that its maximum is 1: exp(-1/2 m^2), in [0, 1].
  double ScaledDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const;

  // Marginal over the listed dimensions (in that order): N(mean[dims], covariance[dims, dims]).
  Gaussian Marginal(const std::vector<int>& dims) const;
  // Conditional of the other dimensions (ascending order) given x[given_dims] = values:
  // mean_a + S_ab S_bb^-1 (values - mean_b), S_aa - S_ab S_bb^-1 S_ba (Schur complement).
  Gaussian Conditional(const std::vector<int>& given_dims,
                       const Eigen::Ref<const Eigen::VectorXd>& values) const;
  // y = A x + b maps N(m, S) to N(A m + b, A S A^T); A is d' x d.
  Gaussian Affine(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) const;

  // One draw mean + L e, e ~ N(0, I).
  Eigen::VectorXd Sample(std::mt19937_64& rng) const;

 private:
  // covariance_ = L L^T (under a lock shared by all Gaussians; stale only after updates).
  void RestoreCovariance() const;

  Eigen::VectorXd mean_;
  mutable Eigen::MatrixXd covariance_;
  mutable std::atomic<bool> covariance_stale_{false};  // covariance_ lags the factor
  Eigen::MatrixXd l_;
  double log_det_ = 0.0;
  double det_factor_ = 1.0;  // det(covariance) = exp(log_det_) det_factor_
  Eigen::VectorXd inv_diag_;  // 1 / L_ii, for the forward substitutions
  Eigen::MatrixXd scratch_;  // factor under construction in SetInPlace
  Eigen::VectorXd inv_diag_scratch_;  // 1 / L'_ii under construction there
};

// Indices 0..dim-1 that are not in `dims`, ascending.
std::vector<int> ComplementDims(int dim, const std::vector<int>& dims);

}  // namespace dgmm
