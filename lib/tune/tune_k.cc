#include "tune/tune_k.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <sstream>

#include "util/error.h"

namespace dgmm {
namespace {

// Residual of the concave quadratic q(u) = a + b (u - u0) - exp(g) (u - u0)^2 at one evaluation
// (u, L), divided by the scale: parameters {a, b, g}.
struct QuadraticResidual {
  QuadraticResidual(double u, double value, double u0, double scale)
      : du_(u - u0), value_(value), scale_(scale) {}
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    const T q = p[0] + p[1] * du_ - exp(p[2]) * du_ * du_;
    residual[0] = (q - value_) / scale_;
    return true;
  }
  double du_, value_, scale_;
};

// -q(u(s)) with u = lo + (hi - lo) sigmoid(s): maximising q over [lo, hi] without bounds.
class NegatedQuadratic : public ceres::FirstOrderFunction {
 public:
  NegatedQuadratic(double b, double c, double u0, double lo, double hi)
      : b_(b), c_(c), u0_(u0), lo_(lo), hi_(hi) {}
  bool Evaluate(const double* s, double* cost, double* gradient) const override {
    const double sigma = 1.0 / (1.0 + std::exp(-s[0]));
    const double du = lo_ + (hi_ - lo_) * sigma - u0_;
    cost[0] = -(b_ * du + c_ * du * du);
    if (gradient) gradient[0] = -(b_ + 2 * c_ * du) * (hi_ - lo_) * sigma * (1 - sigma);
    return true;
  }
  int NumParameters() const override { return 1; }

 private:
  double b_, c_, u0_, lo_, hi_;
};

TuneKPoint ToPoint(double k, const CvScore& score, const char* role) {
  return {k, score.mean, score.sd, score.standard_error, role};
}

}  // namespace

bool TuneKOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  CvOptions probe = cv;
  probe.em_baseline = false;
  if (!probe.IsValid(error)) return false;
  if (!(k_min > 0) || !(k_max > k_min) || !std::isfinite(k_max)) {
    return fail("need 0 < k_min < k_max (finite)");
  }
  if (grid_points < 3) return fail("grid_points must be >= 3");
  if (refine_points < 0) return fail("refine_points must be >= 0");
  return true;
}

double TuneKSummary::Smoothed(double k) const {
  const double du = std::log(k) - u0;
  return a + b * du + c * du * du;
}

void FitAndMaximise(const std::vector<TuneKPoint>& points, double bracket_lo, double bracket_hi,
                    double scale, TuneKSummary* summary) {
  assert(!points.empty() && scale > 0 && bracket_lo > 0 && bracket_hi >= bracket_lo);
  const auto best = std::max_element(
      points.begin(), points.end(),
      [](const auto& p, const auto& q) { return p.log_likelihood < q.log_likelihood; });
  const double u0 = std::log(best->k);
  const double lo = std::log(bracket_lo), hi = std::log(bracket_hi);
  // The evaluations within twice the bracket's half-width of the best (at least three).
  const double reach = std::max(hi - u0, u0 - lo) * 2 + 1e-9;
  std::vector<const TuneKPoint*> near;
  for (const auto& p : points) {
    if (std::abs(std::log(p.k) - u0) <= reach) near.push_back(&p);
  }
  if (near.size() < 3) {
    near.clear();
    for (const auto& p : points) near.push_back(&p);
  }
  double lowest = best->log_likelihood, widest = 1e-6;
  for (const auto* p : near) {
    lowest = std::min(lowest, p->log_likelihood);
    widest = std::max(widest, std::abs(std::log(p->k) - u0));
  }
  double params[3] = {
      best->log_likelihood, 0.0,
      std::log(std::max((best->log_likelihood - lowest) / (widest * widest), 1e-3 * scale))};
  ceres::Problem problem;
  for (const auto* p : near) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<QuadraticResidual, 1, 3>(
            new QuadraticResidual(std::log(p->k), p->log_likelihood, u0, scale)),
        new ceres::CauchyLoss(1.0), params);
  }
  ceres::Solver::Options fit_options;
  fit_options.max_num_iterations = 200;
  ceres::Solver::Summary fit_summary;
  ceres::Solve(fit_options, &problem, &fit_summary);
  summary->u0 = u0;
  summary->a = params[0];
  summary->b = params[1];
  summary->c = -std::exp(params[2]);
  summary->fit_points = static_cast<int>(near.size());
  summary->fit_report = fit_summary.BriefReport();

  if (hi - lo < 1e-12) {
    summary->k = std::exp(lo);
    summary->maximise_report = "empty bracket";
    return;
  }
  const double start = std::clamp((u0 - lo) / (hi - lo), 0.01, 0.99);
  double s = std::log(start / (1 - start));
  ceres::GradientProblem objective(new NegatedQuadratic(summary->b, summary->c, u0, lo, hi));
  ceres::GradientProblemSolver::Options max_options;
  max_options.max_num_iterations = 200;
  max_options.gradient_tolerance = 1e-12;
  max_options.function_tolerance = 1e-14;
  ceres::GradientProblemSolver::Summary max_summary;
  ceres::Solve(max_options, objective, &s, &max_summary);
  summary->k = std::exp(lo + (hi - lo) / (1.0 + std::exp(-s)));
  summary->maximise_report = max_summary.BriefReport();
}

TuneKSummary TuneK(const SampleSet& set, const TuneKOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "tune-k", error);
  if (set.size() == 0) throw MakeInputError("", "sample set", "is empty");
  const auto start = std::chrono::steady_clock::now();
  TuneKSummary summary;
  summary.with_terrain = options.with_terrain && set.terrain_dim() > 0;
  CvOptions cv = options.cv;
  cv.em_baseline = false;
  cv.with_terrain = summary.with_terrain;
  cv.without_terrain = !summary.with_terrain;
  const int planned = options.grid_points + options.refine_points + 1;
  int evaluations = 0;
  auto evaluate = [&](double k, const char* role) {
    if (options.progress) options.progress(evaluations, planned);
    ++evaluations;
    cv.dgmm.k = k;
    const CvSummary result = CrossValidate(set, cv);
    summary.folds = result.folds;
    summary.repeats = result.repeats;
    summary.samples = result.samples;
    return ToPoint(k, summary.with_terrain ? result.dgmm_with_terrain : result.dgmm_without_terrain,
                   role);
  };

  // (1) coarse grid in log k; (2) bracket around its best point.
  const double u_min = std::log(options.k_min), u_max = std::log(options.k_max);
  const double step = (u_max - u_min) / (options.grid_points - 1);
  std::vector<TuneKPoint> points;
  for (int i = 0; i < options.grid_points; ++i) {
    points.push_back(evaluate(std::exp(u_min + i * step), "grid"));
  }
  int best = 0;
  for (int i = 1; i < options.grid_points; ++i) {
    if (points[i].log_likelihood > points[best].log_likelihood) best = i;
  }
  summary.at_grid_edge = best == 0 || best == options.grid_points - 1;
  const double lo = u_min + std::max(best - 1, 0) * step;
  const double hi = u_min + std::min(best + 1, options.grid_points - 1) * step;
  summary.bracket_lo = std::exp(lo);
  summary.bracket_hi = std::exp(hi);
  const double scale = std::max(points[best].standard_error, 1e-6);
  // (3) a few more evaluations inside the bracket, (4) smooth fit and its maximum.
  for (int j = 1; j <= options.refine_points; ++j) {
    points.push_back(
        evaluate(std::exp(lo + (hi - lo) * j / (options.refine_points + 1.0)), "refine"));
  }
  FitAndMaximise(points, summary.bracket_lo, summary.bracket_hi, scale, &summary);
  // (5) the chosen k, cross-validated with the same folds and random numbers.
  const TuneKPoint chosen = evaluate(summary.k, "chosen");
  points.push_back(chosen);
  summary.log_likelihood = chosen.log_likelihood;
  summary.standard_error = chosen.standard_error;
  summary.sd = chosen.sd;
  std::sort(points.begin(), points.end(), [](const auto& p, const auto& q) { return p.k < q.k; });
  summary.curve = points;
  const auto top = std::max_element(points.begin(), points.end(), [](const auto& p, const auto& q) {
    return p.log_likelihood < q.log_likelihood;
  });
  summary.best_evaluated_k = top->k;
  summary.best_evaluated_log_likelihood = top->log_likelihood;
  if (options.progress) options.progress(planned, planned);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::string TuneKSummary::BriefReport() const {
  std::ostringstream out;
  out << "k = " << k << ": held-out log-likelihood " << log_likelihood << " +- " << standard_error
      << " (" << repeats << " x " << folds << "-fold, " << (with_terrain ? "with" : "without")
      << " terrain); bracket [" << bracket_lo << ", " << bracket_hi << "]"
      << (at_grid_edge ? " at the edge of the grid" : "") << "; " << curve.size() << " evaluations";
  return out.str();
}

}  // namespace dgmm
