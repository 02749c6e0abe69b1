#include "tune/quadratic_surrogate.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

namespace dgmm {
namespace {

// Parameter layout: p[0] = a, p[1..D] = b, then L(i, j) for j <= i, row by row.
int LIndex(int dims, int i, int j) { return 1 + dims + i * (i + 1) / 2 + j; }

// (q(v) - y) / scale at one evaluation, with dv = v - v0 fixed.
struct SurrogateResidual {
  SurrogateResidual(Eigen::VectorXd dv, double y, double scale)
      : dv_(std::move(dv)), y_(y), scale_(scale) {}
  template <typename T>
  bool operator()(T const* const* parameters, T* residual) const {
    const T* p = parameters[0];
    const int dims = static_cast<int>(dv_.size());
    T value = p[0];
    for (int i = 0; i < dims; ++i) value += p[1 + i] * dv_[i];
    T quadratic(0.0);  // |L^T dv|^2
    for (int j = 0; j < dims; ++j) {
      T w(0.0);
      for (int i = j; i < dims; ++i) w += p[LIndex(dims, i, j)] * dv_[i];
      quadratic += w * w;
    }
    residual[0] = (value - 0.5 * quadratic - y_) / scale_;
    return true;
  }
  Eigen::VectorXd dv_;
  double y_, scale_;
};

// a - q(v(s)), v = lo + (hi - lo) sigmoid(s) per coordinate (without the constant a, so the
// solver's relative tolerances act on the surrogate's variation, not on the level of L).
class NegatedSurrogate : public ceres::FirstOrderFunction {
 public:
  NegatedSurrogate(const QuadraticSurrogate& q, Eigen::VectorXd lo, Eigen::VectorXd hi)
      : q_(q), lo_(std::move(lo)), hi_(std::move(hi)) {}
  Eigen::VectorXd Point(const double* s) const {
    Eigen::VectorXd v(lo_.size());
    for (int i = 0; i < v.size(); ++i) v[i] = lo_[i] + (hi_[i] - lo_[i]) / (1 + std::exp(-s[i]));
    return v;
  }
  bool Evaluate(const double* s, double* cost, double* gradient) const override {
    const Eigen::VectorXd v = Point(s);
    cost[0] = q_.a - q_(v);
    if (gradient) {
      const Eigen::VectorXd g = q_.b + q_.Hessian() * (v - q_.v0);
      for (int i = 0; i < v.size(); ++i) {
        const double sigma = 1 / (1 + std::exp(-s[i]));
        gradient[i] = -g[i] * (hi_[i] - lo_[i]) * sigma * (1 - sigma);
      }
    }
    return true;
  }
  int NumParameters() const override { return static_cast<int>(lo_.size()); }

 private:
  QuadraticSurrogate q_;
  Eigen::VectorXd lo_, hi_;
};

}  // namespace

double QuadraticSurrogate::operator()(const Eigen::VectorXd& v) const {
  const Eigen::VectorXd dv = v - v0;
  return a + b.dot(dv) - 0.5 * (L.transpose() * dv).squaredNorm();
}

Eigen::MatrixXd QuadraticSurrogate::Hessian() const { return -L * L.transpose(); }

int QuadraticSurrogateParameters(int dims) { return 1 + dims + dims * (dims + 1) / 2; }

SurrogateMaximum FitAndMaximiseQuadratic(const Eigen::MatrixXd& V, const Eigen::VectorXd& y,
                                         double scale) {
  const int n = static_cast<int>(V.rows()), dims = static_cast<int>(V.cols());
  assert(n >= 1 && dims >= 1 && y.size() == n && scale > 0);
  int best = 0;
  for (int j = 1; j < n; ++j) {
    if (y[j] > y[best]) best = j;
  }
  SurrogateMaximum out;
  out.fit_points = n;
  out.box_lo = V.colwise().minCoeff().transpose();
  out.box_hi = V.colwise().maxCoeff().transpose();
  const Eigen::VectorXd v0 = V.row(best).transpose();
  // Start: flat at the best value, curvature from the drop to the lowest over each coordinate's
  // reach (at least a thousandth of the scale), no slope, no coupling.
  std::vector<double> p(QuadraticSurrogateParameters(dims), 0.0);
  p[0] = y[best];
  const double drop = std::max(y[best] - y.minCoeff(), 1e-3 * scale);
  for (int i = 0; i < dims; ++i) {
    const double reach = std::max((V.col(i).array() - v0[i]).abs().maxCoeff(), 1e-6);
    p[LIndex(dims, i, i)] = std::sqrt(2 * drop / dims) / reach;
  }
  ceres::Problem problem;
  for (int j = 0; j < n; ++j) {
    auto* cost = new ceres::DynamicAutoDiffCostFunction<SurrogateResidual>(
        new SurrogateResidual(V.row(j).transpose() - v0, y[j], scale));
    cost->AddParameterBlock(static_cast<int>(p.size()));
    cost->SetNumResiduals(1);
    problem.AddResidualBlock(cost, new ceres::CauchyLoss(1.0), p.data());
  }
  ceres::Solver::Options fit_options;
  fit_options.max_num_iterations = 500;
  ceres::Solver::Summary fit_summary;
  ceres::Solve(fit_options, &problem, &fit_summary);
  out.fit_report = fit_summary.BriefReport();
  QuadraticSurrogate& q = out.q;
  q.a = p[0];
  q.v0 = v0;
  q.b = Eigen::Map<const Eigen::VectorXd>(p.data() + 1, dims);
  q.L = Eigen::MatrixXd::Zero(dims, dims);
  for (int i = 0; i < dims; ++i) {
    for (int j = 0; j <= i; ++j) q.L(i, j) = p[LIndex(dims, i, j)];
  }

  // Maximise over the box from the best evaluation (a degenerate coordinate stays fixed).
  Eigen::VectorXd lo = out.box_lo, hi = out.box_hi;
  std::vector<double> s(dims, 0.0);
  for (int i = 0; i < dims; ++i) {
    if (hi[i] - lo[i] < 1e-12) hi[i] = lo[i];
    const double start =
        hi[i] > lo[i] ? std::clamp((v0[i] - lo[i]) / (hi[i] - lo[i]), 0.01, 0.99) : 0.5;
    s[i] = std::log(start / (1 - start));
  }
  auto* objective = new NegatedSurrogate(q, lo, hi);
  ceres::GradientProblem problem_max(objective);
  ceres::GradientProblemSolver::Options max_options;
  max_options.max_num_iterations = 500;
  // In nats of the surrogate: far below any difference a cross-validation can resolve; tighter
  // tolerances only make the line search chase round-off where a sigmoid saturates at a face.
  max_options.gradient_tolerance = 1e-8;
  max_options.function_tolerance = 1e-10;
  ceres::GradientProblemSolver::Summary max_summary;
  ceres::Solve(max_options, problem_max, s.data(), &max_summary);
  out.maximise_report = max_summary.BriefReport();
  out.v = objective->Point(s.data());
  out.value = q(out.v);
  return out;
}

}  // namespace dgmm
