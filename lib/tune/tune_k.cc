#include "tune/tune_k.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>

#include "tune/quadratic_surrogate.h"
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

TuneKPoint ToPoint(const DgmmOptions& o, const CvScore& score, const char* role) {
  return {o.k,
          score.mean,
          score.sd,
          score.standard_error,
          role,
          score.mean_components,
          o.initial_covariance_fraction,
          o.prior_pseudo_count};
}

std::string Num(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
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
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (points[i].log_likelihood < floor) continue;
    p.members.push_back(i);
    const TuneKPoint& q = points[i];
    if (p.simplest < 0 || q.components < points[p.simplest].components ||
        (q.components == points[p.simplest].components &&
         q.log_likelihood > points[p.simplest].log_likelihood)) {
      p.simplest = i;
    }
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

// One evaluation per (k, f, nu0): CrossValidate with the same folds and random numbers.
class Evaluator {
 public:
  Evaluator(const SampleSet& set, CvOptions cv, const TuneKOptions& options, TuneKSummary* summary)
      : set_(set), cv_(std::move(cv)), options_(options), summary_(summary) {}
  DgmmOptions& dgmm() { return cv_.dgmm; }
  // The cached evaluation at (k, f, nu0) (equal to within a relative 1e-9, so a design point
  // computed as exp(log k + step) finds the grid's k), else a new cross-validation.
  TuneKPoint operator()(double k, const char* role) {
    cv_.dgmm.k = k;
    const double f = cv_.dgmm.initial_covariance_fraction, nu = cv_.dgmm.prior_pseudo_count;
    auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); };
    for (const TuneKPoint& p : cache_) {
      if (same(p.k, k) && same(p.init_scale, f) && same(p.prior_count, nu)) return p;
    }
    if (options_.progress) options_.progress(static_cast<int>(cache_.size()), -1);
    const CvSummary result = CrossValidate(set_, cv_);
    summary_->folds = result.folds;
    summary_->repeats = result.repeats;
    summary_->samples = result.samples;
    summary_->folds_by = result.folds_by;
    summary_->evaluations = static_cast<int>(cache_.size()) + 1;
    cache_.push_back(ToPoint(
        cv_.dgmm, summary_->with_terrain ? result.dgmm_with_terrain : result.dgmm_without_terrain,
        role));
    return cache_.back();
  }
  // Every evaluation so far, in order.
  const std::vector<TuneKPoint>& all() const { return cache_; }
  double Tolerance(const std::vector<TuneKPoint>& pts) const {
    if (options_.plateau_tolerance > 0) return options_.plateau_tolerance;
    return std::max(pts[FindPlateau(pts, 0.0).best].standard_error, 1e-9);
  }

 private:
  const SampleSet& set_;
  CvOptions cv_;
  const TuneKOptions& options_;
  TuneKSummary* summary_;
  std::vector<TuneKPoint> cache_;
};

// The k step at the evaluator's f and nu0: grid, bracket, refinement, Ceres fit, plateau rule.
// Fills the k fields of *summary and returns the chosen point.
TuneKPoint ChooseK(const TuneKOptions& options, Evaluator& evaluate, TuneKSummary* summary) {
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
  summary->at_grid_edge = best == 0 || best == options.grid_points - 1;
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
  // Plateau rule: several evaluations equivalent to the best -> the simplest of them.
  summary->plateau_tolerance = evaluate.Tolerance(points);
  const Plateau plateau = FindPlateau(points, summary->plateau_tolerance);
  summary->plateau = plateau.flat;
  summary->plateau_k_lo = plateau.k_lo;
  summary->plateau_k_hi = plateau.k_hi;
  summary->plateau_points = static_cast<int>(plateau.members.size());
  TuneKPoint chosen;
  if (plateau.flat) {
    chosen = points[plateau.simplest];
    summary->k = chosen.k;
    summary->k_rule = "plateau: " + std::to_string(plateau.members.size()) +
                      " evaluations within " + Num(summary->plateau_tolerance) +
                      " of the best, k in [" + Num(plateau.k_lo) + ", " + Num(plateau.k_hi) +
                      "]; chose the simplest (fewest Gaussians, " + Num(chosen.components) +
                      " per command)";
  } else {
    summary->k_rule = "maximum of the Ceres quadratic fit (no other evaluation within " +
                      Num(summary->plateau_tolerance) + " of the best)";
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
                            Evaluator& evaluate, std::vector<TuneKPoint>* curve, bool* flat) {
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

// The typical step of a geometric grid in log units: the median log ratio of neighbours (log 3
// for a grid of fewer than two values).
double LogGridStep(std::vector<double> grid) {
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  std::vector<double> steps;
  for (size_t i = 1; i < grid.size(); ++i) steps.push_back(std::log(grid[i] / grid[i - 1]));
  if (steps.empty()) return std::log(3.0);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

// The joint step (tune_k.h, 3.): a design around *chosen, a concave quadratic surrogate fitted to
// the evaluations in its box and maximised there (Ceres), L evaluated at the maximiser, and the
// acceptance and plateau rules. Updates *chosen and summary->joint.
void JointStep(const TuneKOptions& options, bool tune_scale, bool tune_prior, Evaluator& evaluate,
               TuneKPoint* chosen, TuneKSummary* summary) {
  TuneJointStep& joint = summary->joint;
  joint.run = true;
  joint.start = *chosen;
  const int before = summary->evaluations;
  // Coordinates: which (0: k, 1: f, 2: nu0), step, and bounds in log units.
  struct Axis {
    int which;
    double step, lo, hi;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<Axis> axes = {
      {0, (std::log(options.k_max) - std::log(options.k_min)) / (options.grid_points - 1),
       std::log(options.k_min), std::log(options.k_max)}};
  joint.coordinates = {"log k"};
  if (tune_scale) {
    axes.push_back({1, LogGridStep(options.init_scales), -kInf, kInf});
    joint.coordinates.push_back("log f");
  }
  if (tune_prior) {
    axes.push_back({2, LogGridStep(options.prior_counts), -kInf, kInf});
    joint.coordinates.push_back("log nu0");
  }
  const int dims = static_cast<int>(axes.size());
  auto value = [](const TuneKPoint& p, int which) {
    return std::log(which == 0 ? p.k : which == 1 ? p.init_scale : p.prior_count);
  };
  auto evaluate_at = [&](const Eigen::VectorXd& v, const char* role) {
    double k = 0;
    for (int i = 0; i < dims; ++i) {
      if (axes[i].which == 0) k = std::exp(v[i]);
      if (axes[i].which == 1) evaluate.dgmm().initial_covariance_fraction = std::exp(v[i]);
      if (axes[i].which == 2) evaluate.dgmm().prior_pseudo_count = std::exp(v[i]);
    }
    return evaluate(k, role);
  };
  auto same_point = [](const TuneKPoint& p, const TuneKPoint& q) {
    return p.k == q.k && p.init_scale == q.init_scale && p.prior_count == q.prior_count;
  };
  for (int round = 0; round < options.joint_rounds; ++round) {
    joint.rounds = round + 1;
    // Design centre m: the choice, moved inward so that m +- step stays within the bounds; the
    // step halves in each round.
    Eigen::VectorXd m(dims), step(dims);
    for (int i = 0; i < dims; ++i) {
      const Axis& a = axes[i];
      step[i] = std::min(std::ldexp(a.step, -round), (a.hi - a.lo) / 2);
      m[i] = std::clamp(value(*chosen, a.which), a.lo + step[i], a.hi - step[i]);
    }
    evaluate_at(m, "joint");
    for (int i = 0; i < dims; ++i) {
      for (int sign : {-1, 1}) {
        evaluate_at(m + sign * step[i] * Eigen::VectorXd::Unit(dims, i), "joint");
      }
    }
    for (int corner = 0; corner < (1 << dims); ++corner) {
      Eigen::VectorXd v = m;
      for (int i = 0; i < dims; ++i) v[i] += (corner >> i & 1 ? 1 : -1) * step[i];
      evaluate_at(v, "joint");
    }
    // Every evaluation in the design's box (the f and nu0 not tuned are fixed throughout).
    std::vector<TuneKPoint> in_box;
    for (const TuneKPoint& p : evaluate.all()) {
      bool inside = true;
      for (int i = 0; i < dims; ++i) {
        inside = inside && std::abs(value(p, axes[i].which) - m[i]) <= step[i] * (1 + 1e-9);
      }
      if (inside) in_box.push_back(p);
    }
    Eigen::MatrixXd V(in_box.size(), dims);
    Eigen::VectorXd y(in_box.size());
    for (size_t j = 0; j < in_box.size(); ++j) {
      for (int i = 0; i < dims; ++i) V(j, i) = value(in_box[j], axes[i].which);
      y[j] = in_box[j].log_likelihood;
    }
    const double scale = std::max(in_box[FindPlateau(in_box, 0.0).best].standard_error, 1e-6);
    const SurrogateMaximum surrogate = FitAndMaximiseQuadratic(V, y, scale);
    joint.fit_points = surrogate.fit_points;
    joint.fit_report = surrogate.fit_report;
    joint.maximise_report = surrogate.maximise_report;
    joint.surrogate_maximum = surrogate.value;
    const TuneKPoint at_max = evaluate_at(surrogate.v, "joint-max");
    joint.surrogate_k = at_max.k;
    joint.surrogate_init_scale = at_max.init_scale;
    joint.surrogate_prior_count = at_max.prior_count;
    joint.evaluated_log_likelihood = at_max.log_likelihood;
    joint.evaluated_standard_error = at_max.standard_error;
    in_box.push_back(at_max);
    for (const TuneKPoint& p : in_box) {
      if (std::none_of(joint.points.begin(), joint.points.end(),
                       [&](const TuneKPoint& q) { return same_point(p, q); })) {
        joint.points.push_back(p);
      }
    }

    // Acceptance and the plateau rule over every evaluation of the step so far.
    joint.tolerance = evaluate.Tolerance(joint.points);
    joint.plateau = FindPlateau(joint.points, joint.tolerance);
    const TuneKPoint& best = joint.points[joint.plateau.best];
    const TuneKPoint& simplest = joint.points[joint.plateau.simplest];
    std::string rule = "round " + std::to_string(round + 1) + " (step x " +
                       Num(std::ldexp(1.0, -round)) + "): the surrogate's maximum " +
                       Num(surrogate.value) + " at k = " + Num(at_max.k) +
                       ", f = " + Num(at_max.init_scale) + ", nu0 = " + Num(at_max.prior_count) +
                       " evaluates to " + Num(at_max.log_likelihood) + "; ";
    if (best.log_likelihood > chosen->log_likelihood + joint.tolerance) {
      joint.accepted = true;
      *chosen = joint.plateau.flat ? simplest : best;
      rule += "an evaluation beats the choice by more than " + Num(joint.tolerance) +
              ": moved to " +
              (joint.plateau.flat ? "the simplest model of the plateau" : "the best evaluation");
    } else if (simplest.components < chosen->components - 1e-9) {
      *chosen = simplest;
      rule += "nothing beats the choice by more than " + Num(joint.tolerance) +
              "; moved to a strictly simpler equivalent model (plateau rule)";
    } else {
      rule += "nothing beats the choice by more than " + Num(joint.tolerance) + ": kept it";
    }
    joint.rule += (round > 0 ? "; " : "") + rule;
  }
  joint.evaluations = summary->evaluations - before;
  evaluate.dgmm().initial_covariance_fraction = chosen->init_scale;
  evaluate.dgmm().prior_pseudo_count = chosen->prior_count;
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
  Evaluator evaluate(set, cv, options, &summary);

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

std::string TuneKSummary::BriefReport() const {
  std::ostringstream out;
  out << "k = " << k << ": held-out log-likelihood " << log_likelihood << " +- " << standard_error
      << " (" << repeats << " x " << folds << "-fold, " << (with_terrain ? "with" : "without")
      << " terrain); bracket [" << bracket_lo << ", " << bracket_hi << "]"
      << (at_grid_edge ? " at the edge of the grid" : "") << "; " << curve.size()
      << " evaluations of k; k chosen by " << k_rule << "; " << evaluations
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
