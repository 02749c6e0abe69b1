#include "tune/joint_step.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "tune/quadratic_surrogate.h"

namespace dgmm {

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

namespace {

// One coordinate of the joint step: which (0: k, 1: f, 2: nu0), its step and bounds in log units.
struct Axis {
  int which;
  double step, lo, hi;
};

double AxisValue(const TuneKPoint& p, int which) {
  return std::log(which == 0 ? p.k : which == 1 ? p.init_scale : p.prior_count);
}

std::vector<Axis> JointAxes(const TuneKOptions& options, bool tune_scale, bool tune_prior,
                            std::vector<std::string>* names) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<Axis> axes = {{0, (std::log(options.k_max) - std::log(options.k_min)) / (options.grid_points - 1),
                             std::log(options.k_min), std::log(options.k_max)}};
  *names = {"log k"};
  if (tune_scale) {
    axes.push_back({1, LogGridStep(options.init_scales), -kInf, kInf});
    names->push_back("log f");
  }
  if (tune_prior) {
    axes.push_back({2, LogGridStep(options.prior_counts), -kInf, kInf});
    names->push_back("log nu0");
  }
  return axes;
}

// L cross-validated at log coordinates v (the f and nu0 not tuned stay as they are).
TuneKPoint EvaluateAt(const std::vector<Axis>& axes, TuneEvaluator& evaluate, const Eigen::VectorXd& v,
                      const char* role) {
  double k = 0;
  for (size_t i = 0; i < axes.size(); ++i) {
    if (axes[i].which == 0) k = std::exp(v[i]);
    if (axes[i].which == 1) evaluate.dgmm().initial_covariance_fraction = std::exp(v[i]);
    if (axes[i].which == 2) evaluate.dgmm().prior_pseudo_count = std::exp(v[i]);
  }
  return evaluate(k, role);
}

// The design around m: its centre, the star m +- step along each axis and the box's corners.
void EvaluateDesign(const std::vector<Axis>& axes, TuneEvaluator& evaluate, const Eigen::VectorXd& m,
                    const Eigen::VectorXd& step) {
  const int dims = static_cast<int>(axes.size());
  EvaluateAt(axes, evaluate, m, "joint");
  for (int i = 0; i < dims; ++i) {
    for (int sign : {-1, 1}) EvaluateAt(axes, evaluate, m + sign * step[i] * Eigen::VectorXd::Unit(dims, i), "joint");
  }
  for (int corner = 0; corner < (1 << dims); ++corner) {
    Eigen::VectorXd v = m;
    for (int i = 0; i < dims; ++i) v[i] += (corner >> i & 1 ? 1 : -1) * step[i];
    EvaluateAt(axes, evaluate, v, "joint");
  }
}

// Every evaluation so far inside the box m +- step.
std::vector<TuneKPoint> PointsInBox(const std::vector<Axis>& axes, const std::vector<TuneKPoint>& all,
                                    const Eigen::VectorXd& m, const Eigen::VectorXd& step) {
  std::vector<TuneKPoint> in_box;
  for (const TuneKPoint& p : all) {
    bool inside = true;
    for (size_t i = 0; i < axes.size(); ++i) {
      inside = inside && std::abs(AxisValue(p, axes[i].which) - m[i]) <= step[i] * (1 + 1e-9);
    }
    if (inside) in_box.push_back(p);
  }
  return in_box;
}

// The concave quadratic surrogate of L over the box's evaluations, maximised in the box (Ceres),
// and L evaluated at its maximiser; recorded in *joint.
TuneKPoint MaximiseSurrogate(const std::vector<Axis>& axes, TuneEvaluator& evaluate,
                             const std::vector<TuneKPoint>& in_box, TuneJointStep* joint) {
  const int dims = static_cast<int>(axes.size());
  Eigen::MatrixXd V(in_box.size(), dims);
  Eigen::VectorXd y(in_box.size());
  for (size_t j = 0; j < in_box.size(); ++j) {
    for (int i = 0; i < dims; ++i) V(j, i) = AxisValue(in_box[j], axes[i].which);
    y[j] = in_box[j].log_likelihood;
  }
  const double scale = std::max(in_box[FindPlateau(in_box, 0.0).best].standard_error, 1e-6);
  const SurrogateMaximum surrogate = FitAndMaximiseQuadratic(V, y, scale);
  joint->fit_points = surrogate.fit_points;
  joint->fit_report = surrogate.fit_report;
  joint->maximise_report = surrogate.maximise_report;
  joint->surrogate_maximum = surrogate.value;
  const TuneKPoint at_max = EvaluateAt(axes, evaluate, surrogate.v, "joint-max");
  joint->surrogate_k = at_max.k;
  joint->surrogate_init_scale = at_max.init_scale;
  joint->surrogate_prior_count = at_max.prior_count;
  joint->evaluated_log_likelihood = at_max.log_likelihood;
  joint->evaluated_standard_error = at_max.standard_error;
  return at_max;
}

void AddNewPoints(const std::vector<TuneKPoint>& from, std::vector<TuneKPoint>* points) {
  auto same = [](const TuneKPoint& p, const TuneKPoint& q) {
    return p.k == q.k && p.init_scale == q.init_scale && p.prior_count == q.prior_count;
  };
  for (const TuneKPoint& p : from) {
    if (std::none_of(points->begin(), points->end(), [&](const TuneKPoint& q) { return same(p, q); })) {
      points->push_back(p);
    }
  }
}

// Acceptance and the plateau rule over every evaluation of the step so far; moves *chosen and
// returns the round's sentence.
std::string AcceptOrKeep(TuneEvaluator& evaluate, int round, const TuneKPoint& at_max, TuneJointStep* joint,
                         TuneKPoint* chosen) {
  joint->tolerance = evaluate.Tolerance(joint->points);
  joint->plateau = FindPlateau(joint->points, joint->tolerance);
  const TuneKPoint& best = joint->points[joint->plateau.best];
  const TuneKPoint& simplest = joint->points[joint->plateau.simplest];
  std::string rule = "round " + std::to_string(round + 1) + " (step x " + ShortNumber(std::ldexp(1.0, -round)) +
                     "): the surrogate's maximum " + ShortNumber(joint->surrogate_maximum) +
                     " at k = " + ShortNumber(at_max.k) + ", f = " + ShortNumber(at_max.init_scale) +
                     ", nu0 = " + ShortNumber(at_max.prior_count) + " evaluates to " +
                     ShortNumber(at_max.log_likelihood) + "; ";
  const std::string tolerance = ShortNumber(joint->tolerance);
  if (best.log_likelihood > chosen->log_likelihood + joint->tolerance) {
    joint->accepted = true;
    *chosen = joint->plateau.flat ? simplest : best;
    return rule + "an evaluation beats the choice by more than " + tolerance + ": moved to " +
           (joint->plateau.flat ? "the simplest model of the plateau" : "the best evaluation");
  }
  if (simplest.components < chosen->components - kSameModelSize) {
    *chosen = simplest;
    return rule + "nothing beats the choice by more than " + tolerance +
           "; moved to a strictly simpler equivalent model (plateau rule)";
  }
  return rule + "nothing beats the choice by more than " + tolerance + ": kept it";
}

}  // namespace

// The joint step (tune_k.h, 3.): per round, a design around *chosen (its centre moved inward so
// that m +- step stays within the bounds; the step halves each round), the quadratic surrogate
// maximised in its box, then the acceptance and plateau rules. Updates *chosen and summary->joint.
void JointStep(const TuneKOptions& options, bool tune_scale, bool tune_prior,
               TuneEvaluator& evaluate, TuneKPoint* chosen, TuneKSummary* summary) {
  TuneJointStep& joint = summary->joint;
  joint.run = true;
  joint.start = *chosen;
  const int before = summary->evaluations;
  const std::vector<Axis> axes = JointAxes(options, tune_scale, tune_prior, &joint.coordinates);
  const int dims = static_cast<int>(axes.size());
  for (int round = 0; round < options.joint_rounds; ++round) {
    joint.rounds = round + 1;
    Eigen::VectorXd m(dims), step(dims);
    for (int i = 0; i < dims; ++i) {
      const Axis& a = axes[i];
      step[i] = std::min(std::ldexp(a.step, -round), (a.hi - a.lo) / 2);
      m[i] = std::clamp(AxisValue(*chosen, a.which), a.lo + step[i], a.hi - step[i]);
    }
    EvaluateDesign(axes, evaluate, m, step);
    std::vector<TuneKPoint> in_box = PointsInBox(axes, evaluate.all(), m, step);
    const TuneKPoint at_max = MaximiseSurrogate(axes, evaluate, in_box, &joint);
    in_box.push_back(at_max);
    AddNewPoints(in_box, &joint.points);
    joint.rule += (round > 0 ? "; " : "") + AcceptOrKeep(evaluate, round, at_max, &joint, chosen);
  }
  joint.evaluations = summary->evaluations - before;
  evaluate.dgmm().initial_covariance_fraction = chosen->init_scale;
  evaluate.dgmm().prior_pseudo_count = chosen->prior_count;
}

}  // namespace dgmm
