#include "core/mise.h"

#include "core/log_sum_exp.h"

#include <Eigen/Cholesky>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace dgmm {
namespace {

constexpr double kLog2Pi = 1.8378770664093454836;

// log N(a; b, S) with S = L L^T factored here; -inf if S does not factor (cannot happen for two
// positive definite summands, but a degenerate input must not crash).
double LogGaussianAt(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const Eigen::MatrixXd& s) {
  Eigen::LLT<Eigen::MatrixXd> llt(s);
  if (llt.info() != Eigen::Success) return -std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd& l = llt.matrixL();
  double log_det = 2.0 * l.diagonal().array().log().sum();
  Eigen::VectorXd r = llt.matrixL().solve(a - b);
  return -0.5 * (static_cast<double>(a.size()) * kLog2Pi + log_det + r.squaredNorm());
}

}  // namespace

double LogOverlapIntegral(const Mixture& p, const Mixture& q) {
  assert(p.dim() == q.dim());
  if (p.empty() || q.empty()) return -std::numeric_limits<double>::infinity();
  const double log_wp = std::log(p.total_weight()), log_wq = std::log(q.total_weight());
  std::vector<double> terms;
  terms.reserve(static_cast<size_t>(p.size()) * q.size());
  for (int i = 0; i < p.size(); ++i) {
    const Gaussian& gi = p.component(i);
    const double log_ai = std::log(p.weight(i)) - log_wp;
    for (int j = 0; j < q.size(); ++j) {
      const Gaussian& gj = q.component(j);
      terms.push_back(log_ai + std::log(q.weight(j)) - log_wq +
                      LogGaussianAt(gi.mean(), gj.mean(), gi.covariance() + gj.covariance()));
    }
  }
  return LogSumExp(terms.data(), static_cast<int>(terms.size()));
}

IseTerms IntegratedSquaredErrorTerms(const Mixture& p, const Mixture& q) {
  IseTerms t;
  t.pp = std::exp(LogOverlapIntegral(p, p));
  t.pq = std::exp(LogOverlapIntegral(p, q));
  t.qq = std::exp(LogOverlapIntegral(q, q));
  t.ise = std::max(0.0, t.pp - 2.0 * t.pq + t.qq);
  return t;
}

double IntegratedSquaredError(const Mixture& p, const Mixture& q) {
  return IntegratedSquaredErrorTerms(p, q).ise;
}

}  // namespace dgmm
