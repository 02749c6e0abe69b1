#include "core/mixture.h"

#include "core/log_sum_exp.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>

namespace dgmm {
namespace {

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

}  // namespace

double Mixture::total_weight() const {
  return std::accumulate(weights_.begin(), weights_.end(), 0.0);
}

void Mixture::Add(double weight, Gaussian g) {
  assert(weight > 0 && std::isfinite(weight));
  if (components_.empty() && dim_ == 0) dim_ = g.dim();
  assert(g.dim() == dim_);
  weights_.push_back(weight);
  components_.push_back(std::move(g));
}

double Mixture::LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  const int k = size();
  if (k == 0) return kNegInf;
  const double log_total = std::log(total_weight());
  // Stack buffer for typical sizes; log-sum-exp over log w_i + log N_i(x).
  constexpr int kStack = 64;
  double buf[kStack];
  Eigen::VectorXd heap;
  double* v = buf;
  if (k > kStack) {
    heap.resize(k);
    v = heap.data();
  }
  for (int i = 0; i < k; ++i) v[i] = std::log(weights_[i]) + components_[i].LogDensity(x);
  return LogSumExp(v, k) - log_total;
}

Eigen::VectorXd Mixture::LogDensity(const Eigen::Ref<const Eigen::MatrixXd>& X) const {
  const int n = static_cast<int>(X.cols());
  if (empty()) return Eigen::VectorXd::Constant(n, kNegInf);
  Eigen::MatrixXd terms(size(), n);
  for (int i = 0; i < size(); ++i) {
    terms.row(i) = (components_[i].LogDensity(X).array() + std::log(weights_[i])).transpose();
  }
  // Log-sum-exp of every column at once (vectorised exp and log over the whole block); a column
  // whose largest term is not finite (-inf: every component zero) keeps that term.
  const Eigen::RowVectorXd top = terms.colwise().maxCoeff();
  const Eigen::RowVectorXd finite_top = top.unaryExpr([](double m) { return std::isfinite(m) ? m : 0.0; });
  const Eigen::ArrayXd lse = (finite_top.array() + (terms.rowwise() - finite_top).array().exp().colwise().sum().log()).transpose();
  const double log_total = std::log(total_weight());
  Eigen::VectorXd out(n);
  for (int j = 0; j < n; ++j) out[j] = (std::isfinite(top[j]) ? lse[j] : top[j]) - log_total;
  return out;
}

Eigen::VectorXd Mixture::LogResponsibilities(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  Eigen::VectorXd v(size());
  for (int i = 0; i < size(); ++i) v[i] = std::log(weights_[i]) + components_[i].LogDensity(x);
  const double lse = LogSumExp(v);
  if (!std::isfinite(lse)) return Eigen::VectorXd::Constant(size(), kNegInf);
  return v.array() - lse;
}

Mixture Mixture::Marginal(const std::vector<int>& dims) const {
  Mixture out(static_cast<int>(dims.size()));
  for (int i = 0; i < size(); ++i) out.Add(weights_[i], components_[i].Marginal(dims));
  return out;
}

Mixture Mixture::Conditional(const std::vector<int>& given_dims,
                             const Eigen::Ref<const Eigen::VectorXd>& values) const {
  const int da = dim_ - static_cast<int>(given_dims.size());
  Mixture out(da);
  if (empty()) return out;
  // log of the new weights w_i N_i(values) (eqs. 16-19), shifted by their maximum so that the
  // largest is 1: the mixture only depends on the weights' ratios, and this never underflows
  // all of them to zero.
  Eigen::VectorXd log_w(size());
  std::vector<Gaussian> conditioned;
  conditioned.reserve(size());
  for (int i = 0; i < size(); ++i) {
    log_w[i] = std::log(weights_[i]) + components_[i].Marginal(given_dims).LogDensity(values);
    conditioned.push_back(components_[i].Conditional(given_dims, values));
  }
  const double m = log_w.maxCoeff();
  for (int i = 0; i < size(); ++i) {
    // A component with weight that is exactly zero in double precision (or NaN values) drops.
    const double w = std::isfinite(m) ? std::exp(log_w[i] - m) : 1.0;
    if (w > 0) out.Add(w, std::move(conditioned[i]));
  }
  return out;
}

Mixture Mixture::Affine(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) const {
  Mixture out(static_cast<int>(A.rows()));
  for (int i = 0; i < size(); ++i) out.Add(weights_[i], components_[i].Affine(A, b));
  return out;
}

Eigen::MatrixXd Mixture::Sample(int n, std::mt19937_64& rng) const {
  assert(!empty() || n == 0);
  Eigen::MatrixXd out(dim_, n);
  if (n == 0) return out;
  std::discrete_distribution<int> pick(weights_.begin(), weights_.end());
  for (int j = 0; j < n; ++j) out.col(j) = components_[pick(rng)].Sample(rng);
  return out;
}

Eigen::MatrixXd Mixture::SampleWithNoise(const Eigen::Ref<const Eigen::MatrixXd>& noise, std::mt19937_64& rng) const {
  assert(noise.rows() == dim_ && (!empty() || noise.cols() == 0));
  Eigen::MatrixXd out(dim_, noise.cols());
  if (noise.cols() == 0) return out;
  std::discrete_distribution<int> pick(weights_.begin(), weights_.end());
  for (Eigen::Index j = 0; j < noise.cols(); ++j) {
    const Gaussian& g = components_[pick(rng)];
    out.col(j) = g.mean() + g.cholesky_l().triangularView<Eigen::Lower>() * noise.col(j);
  }
  return out;
}

Mixture::Mode Mixture::MaxDensity(const ModeSearchOptions& options) const {
  std::vector<Eigen::VectorXd> starts;
  starts.reserve(components_.size());
  for (const Gaussian& g : components_) starts.push_back(g.mean());
  return MaxDensityFrom(starts, options);
}

Mixture::Mode Mixture::MaxDensityFrom(const std::vector<Eigen::VectorXd>& starts,
                                      const ModeSearchOptions& options) const {
  Mode best;
  best.log_density = kNegInf;
  if (empty()) return best;
  const int k = size(), d = dim_;
  // Precisions P_i = S_i^-1 and P_i mu_i, computed once.
  std::vector<Eigen::MatrixXd> precision(k);
  std::vector<Eigen::VectorXd> precision_mean(k);
  for (int i = 0; i < k; ++i) {
    const Eigen::MatrixXd& l = components_[i].cholesky_l();
    Eigen::MatrixXd linv = Eigen::MatrixXd::Identity(d, d);
    l.triangularView<Eigen::Lower>().solveInPlace(linv);
    precision[i] = linv.transpose() * linv;
    precision_mean[i] = precision[i] * components_[i].mean();
  }
  Eigen::MatrixXd a(d, d);
  Eigen::VectorXd b(d);
  for (const Eigen::VectorXd& start : starts) {
    Eigen::VectorXd x = start;
    for (int it = 0; it < options.max_iterations; ++it) {
      // x <- (sum r_i P_i)^-1 sum r_i P_i mu_i, r_i the responsibilities at x. Each step does
      // not decrease p (it is EM on the mode; Carreira-Perpinan 2000).
      const Eigen::VectorXd log_r = LogResponsibilities(x);
      if (!log_r.allFinite()) break;
      a.setZero();
      b.setZero();
      for (int i = 0; i < k; ++i) {
        const double r = std::exp(log_r[i]);
        if (r == 0.0) continue;
        a.noalias() += r * precision[i];
        b.noalias() += r * precision_mean[i];
      }
      Eigen::VectorXd next = a.llt().solve(b);
      if (!next.allFinite()) break;
      const double step = (next - x).norm();
      x = std::move(next);
      if (step < options.tolerance) break;
    }
    const double log_p = LogDensity(x);
    if (log_p > best.log_density || best.x.size() == 0) {
      best.x = x;
      best.log_density = log_p;
    }
  }
  return best;
}

}  // namespace dgmm
