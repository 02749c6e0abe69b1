#include "tune/tune_k.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <tuple>

#include "tune/joint_step.h"
#include "tune/tune_evaluator.h"
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
  if (cycles < 1) return fail("cycles must be >= 1");
  if (joint && joint_rounds < 1) return fail("joint_rounds must be >= 1");
  if (refine_points < 0) return fail("refine_points must be >= 0");
  if (!(plateau_tolerance >= 0) || !std::isfinite(plateau_tolerance)) {
    return fail("plateau_tolerance must be finite and >= 0");
  }
  for (double f : init_scales) {
    if (!(f > 0) || !std::isfinite(f)) return fail("init_scales must be finite and > 0");
  }
  for (double nu : prior_counts) {
    if (!(nu > 0) || !std::isfinite(nu)) return fail("prior_counts must be finite and > 0");
  }
  return true;
}

Plateau FindPlateau(const std::vector<TuneKPoint>& points, double tolerance) {
  Plateau p;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (p.best < 0 || points[i].log_likelihood > points[p.best].log_likelihood) p.best = i;
  }
  if (p.best < 0) return p;
  const double floor = points[p.best].log_likelihood - tolerance;
  double fewest = INFINITY;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (points[i].log_likelihood < floor) continue;
    p.members.push_back(i);
    fewest = std::min(fewest, points[i].components);
  }
  for (int i : p.members) {
    if (points[i].components > fewest + kSameModelSize) continue;
    if (p.simplest < 0 || points[i].log_likelihood > points[p.simplest].log_likelihood) p.simplest = i;
  }
  p.flat = p.members.size() > 1;
  const TuneKPoint& top = points[p.best];
  p.k_lo = p.k_hi = top.k;
  p.init_scale_lo = p.init_scale_hi = top.init_scale;
  p.prior_count_lo = p.prior_count_hi = top.prior_count;
  for (int i : p.members) {
    p.k_lo = std::min(p.k_lo, points[i].k);
    p.k_hi = std::max(p.k_hi, points[i].k);
    p.init_scale_lo = std::min(p.init_scale_lo, points[i].init_scale);
    p.init_scale_hi = std::max(p.init_scale_hi, points[i].init_scale);
    p.prior_count_lo = std::min(p.prior_count_lo, points[i].prior_count);
    p.prior_count_hi = std::max(p.prior_count_hi, points[i].prior_count);
  }
  return p;
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

namespace {

// The k step at the evaluator's f and nu0: grid, bracket, refinement, Ceres fit, plateau rule.
// Fills the k fields of *summary and returns the chosen point.
TuneKPoint ChooseK(const TuneKOptions& options, TuneEvaluator& evaluate, TuneKSummary* summary) {
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
  summary->k_min = options.k_min;
  summary->k_max = options.k_max;
  summary->best_grid_k = points[best].k;
  const double lo = u_min + std::max(best - 1, 0) * step;
  const double hi = u_min + std::min(best + 1, options.grid_points - 1) * step;
  summary->bracket_lo = std::exp(lo);
  summary->bracket_hi = std::exp(hi);
  const double scale = std::max(points[best].standard_error, 1e-6);
  for (int j = 1; j <= options.refine_points; ++j) {
    points.push_back(
        evaluate(std::exp(lo + (hi - lo) * j / (options.refine_points + 1.0)), "refine"));
  }
  FitAndMaximise(points, summary->bracket_lo, summary->bracket_hi, scale, summary);
  summary->quadratic_k = summary->k;
  // Plateau rule: several evaluations equivalent to the best -> the simplest of them.
  summary->plateau_tolerance = evaluate.Tolerance(points);
  summary->plateau_tolerance_is_se = !(options.plateau_tolerance > 0);
  const Plateau plateau = FindPlateau(points, summary->plateau_tolerance);
  summary->plateau = plateau.flat;
  summary->plateau_k_lo = plateau.k_lo;
  summary->plateau_k_hi = plateau.k_hi;
  summary->plateau_points = static_cast<int>(plateau.members.size());
  summary->plateau_spans_grid = plateau.flat && plateau.k_lo <= options.k_min * (1 + 1e-9) &&
                                plateau.k_hi >= options.k_max * (1 - 1e-9);
  TuneKPoint chosen;
  if (plateau.flat) {
    chosen = points[plateau.simplest];
    summary->k = chosen.k;
    summary->k_rule = "plateau: " + std::to_string(plateau.members.size()) +
                      " evaluations within " + ShortNumber(summary->plateau_tolerance) +
                      " of the best, k in [" + ShortNumber(plateau.k_lo) + ", " +
                      ShortNumber(plateau.k_hi) + "]; chose the simplest (fewest Gaussians, " +
                      ShortNumber(chosen.components) + " per command)";
  } else {
    summary->k_rule = "maximum of the Ceres quadratic fit (no other evaluation within " +
                      ShortNumber(summary->plateau_tolerance) + " of the best)";
    chosen = evaluate(summary->k, "chosen");
    points.push_back(chosen);
  }
  std::sort(points.begin(), points.end(), [](const auto& p, const auto& q) { return p.k < q.k; });
  summary->curve = points;
  const auto top = std::max_element(points.begin(), points.end(), [](const auto& p, const auto& q) {
    return p.log_likelihood < q.log_likelihood;
  });
  summary->best_evaluated_k = top->k;
  summary->best_evaluated_log_likelihood = top->log_likelihood;
  return chosen;
}

// A coordinate step at the chosen k over `grid` for one option; same plateau rule.
TuneKPoint ChooseCoordinate(const std::vector<double>& grid, double DgmmOptions::*field,
                            const char* role, const TuneKPoint& start, double k,
                            TuneEvaluator& evaluate, std::vector<TuneKPoint>* curve, bool* flat) {
  std::vector<TuneKPoint> pts = {start};
  const double kept = evaluate.dgmm().*field;
  auto value_of = [&](const TuneKPoint& t) {
    return field == &DgmmOptions::initial_covariance_fraction ? t.init_scale : t.prior_count;
  };
  for (double value : grid) {
    if (value == kept) continue;  // the start point already has it
    evaluate.dgmm().*field = value;
    pts.push_back(evaluate(k, role));
  }
  // The grid is a guess at the data's needs, not a bound: while the best value is the grid's
  // largest (smallest), step on geometrically by the grid's outer ratio, at most kMaxExtension
  // steps, until a step is worse than the best. (On the shipped log the best S0 scale was the
  // grid's top, 10, and the held-out likelihood kept rising beyond it.)
  constexpr int kMaxExtension = 4;
  std::vector<double> sorted = grid;
  sorted.push_back(kept);
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  if (sorted.size() >= 2) {
    for (int direction : {+1, -1}) {
      const double ratio = direction > 0 ? sorted[sorted.size() - 1] / sorted[sorted.size() - 2]
                                         : sorted[0] / sorted[1];
      for (int step = 0; step < kMaxExtension; ++step) {
        const auto best = std::max_element(
            pts.begin(), pts.end(),
            [](const auto& a, const auto& b) { return a.log_likelihood < b.log_likelihood; });
        const auto extreme = std::minmax_element(
            pts.begin(), pts.end(),
            [&](const auto& a, const auto& b) { return value_of(a) < value_of(b); });
        const TuneKPoint& edge = direction > 0 ? *extreme.second : *extreme.first;
        if (value_of(*best) != value_of(edge)) break;
        evaluate.dgmm().*field = value_of(edge) * ratio;
        pts.push_back(evaluate(k, role));
      }
    }
  }
  const Plateau p = FindPlateau(pts, evaluate.Tolerance(pts));
  *flat = p.flat;
  const TuneKPoint pick = pts[p.flat ? p.simplest : p.best];
  evaluate.dgmm().initial_covariance_fraction = pick.init_scale;
  evaluate.dgmm().prior_pseudo_count = pick.prior_count;
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
    return std::tie(a.init_scale, a.prior_count) < std::tie(b.init_scale, b.prior_count);
  });
  *curve = pts;
  return pick;
}

}  // namespace

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
  const bool tune_scale =
      !options.init_scales.empty() &&
      cv.dgmm.initial_covariance_rule == DgmmOptions::InitialCovarianceRule::kData;
  const bool tune_prior = !options.prior_counts.empty() &&
                          cv.dgmm.covariance_rule == DgmmOptions::CovarianceRule::kPrior;
  TuneEvaluator evaluate(set, cv, options, &summary);

  // Cyclic coordinate ascent: k (Ceres + plateau rule), then f, then nu0, repeated until a
  // cycle changes nothing (at most options.cycles).
  TuneKPoint chosen;
  for (int cycle = 0; cycle < options.cycles; ++cycle) {
    summary.cycles = cycle + 1;
    const TuneKPoint before = chosen;
    chosen = ChooseK(options, evaluate, &summary);
    if (tune_scale) {
      chosen = ChooseCoordinate(options.init_scales, &DgmmOptions::initial_covariance_fraction,
                                "scale", chosen, summary.k, evaluate, &summary.scale_curve,
                                &summary.init_scale_plateau);
      summary.init_scale_tuned = true;
    }
    if (tune_prior) {
      chosen =
          ChooseCoordinate(options.prior_counts, &DgmmOptions::prior_pseudo_count, "prior", chosen,
                           summary.k, evaluate, &summary.prior_curve, &summary.prior_count_plateau);
      summary.prior_count_tuned = true;
    }
    if (!tune_scale && !tune_prior) break;  // nothing else moves: one k step is final
    if (cycle > 0 && chosen.k == before.k && chosen.init_scale == before.init_scale &&
        chosen.prior_count == before.prior_count) {
      break;
    }
  }
  if (options.joint) JointStep(options, tune_scale, tune_prior, evaluate, &chosen, &summary);
  summary.k = chosen.k;
  {
    // The chosen k at an end of the grid, else the best grid point at one (either end).
    auto at_low = [&](double k) { return k <= options.k_min * (1 + 1e-9); };
    auto at_high = [&](double k) { return k >= options.k_max * (1 - 1e-9); };
    summary.grid_edge = at_low(summary.k)              ? "low"
                        : at_high(summary.k)           ? "high"
                        : at_low(summary.best_grid_k)  ? "low"
                        : at_high(summary.best_grid_k) ? "high"
                                                       : "";
  }
  summary.init_scale = chosen.init_scale;
  summary.prior_count = chosen.prior_count;
  summary.log_likelihood = chosen.log_likelihood;
  summary.standard_error = chosen.standard_error;
  summary.sd = chosen.sd;
  summary.components = chosen.components;
  if (options.progress) options.progress(summary.evaluations, summary.evaluations);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::string TuneKSummary::PlateauMeaning() const {
  if (!plateau) return "";
  const std::string within = plateau_tolerance_is_se
                                 ? std::string("within 1 SE")
                                 : "within " + ShortNumber(plateau_tolerance) + " nats of the best";
  if (plateau_spans_grid) {
    return "k not identifiable from this data, smallest model " + within + " chosen";
  }
  char range[64];
  std::snprintf(range, sizeof range, "k from %.4g to %.4g", plateau_k_lo, plateau_k_hi);
  return range + (" equally good " + within + ", smallest model there chosen");
}

std::string TuneKSummary::BriefReport() const {
  std::ostringstream out;
  out << "k = " << k << ": held-out log-likelihood " << log_likelihood << " +- " << standard_error
      << " (" << repeats << " x " << folds << "-fold, " << (with_terrain ? "with" : "without")
      << " terrain); bracket [" << bracket_lo << ", " << bracket_hi << "]"
      << (grid_edge.empty() ? "" : "; k at the " + grid_edge + " end of the grid") << "; "
      << curve.size() << " evaluations of k; k chosen by " << k_rule
      << (plateau ? " (" + PlateauMeaning() + ")" : "") << "; " << evaluations
      << " cross-validations in " << cycles << " cycle(s)";
  if (init_scale_tuned) {
    out << "; S0 scale " << init_scale << (init_scale_plateau ? " (simplest of a plateau)" : "");
  }
  if (prior_count_tuned) {
    out << "; nu0 " << prior_count << (prior_count_plateau ? " (simplest of a plateau)" : "");
  }
  if (joint.run) {
    out << "; joint step over (" << joint.coordinates.size() << " coordinates, "
        << joint.evaluations << " new cross-validations): " << joint.rule;
    if (joint.plateau.flat) {
      out << "; joint plateau of " << joint.plateau.members.size() << " evaluations, k in ["
          << joint.plateau.k_lo << ", " << joint.plateau.k_hi << "], f in ["
          << joint.plateau.init_scale_lo << ", " << joint.plateau.init_scale_hi << "], nu0 in ["
          << joint.plateau.prior_count_lo << ", " << joint.plateau.prior_count_hi << "]";
    }
  }
  return out.str();
}

}  // namespace dgmm
