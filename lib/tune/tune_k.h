#pragma once
// `dgmm tune` (alias tune-k): choice of the DGMM merge rate k (t = 1 - (1 - d) exp(-k n)), the
// initial covariance scale f (S0 = f v, --init-cov data) and the prior pseudo-count nu0
// (--covariance prior) by cross-validated held-out log-likelihood L (tune/cross_validation.h),
// with Ceres. Every evaluation is a full cross-validation with the same folds and random numbers
// (common random numbers: the CvOptions seed does not depend on the settings), cached, so
// L(a) - L(b) is a low-noise comparison. L is noisy and piecewise constant in k (a merge decision
// r < t flips only when k crosses a threshold) and often flat.
//
// 1. k step (at the current f, nu0): L on a coarse grid in u = log k; the best grid point
//    brackets the optimum [u_{i-1}, u_{i+1}], which gets `refine_points` more evaluations; Ceres
//    fits q(u) = a + b (u - u0) - exp(g) (u - u0)^2 to the evaluations near the best by robust
//    (Cauchy) least squares scaled by the best's standard error and maximises it over the
//    bracket (u = lo + (hi - lo) sigmoid(s)); L is evaluated there.
// 2. f step, then nu0 step (at the chosen k): grids, extended geometrically beyond a best edge.
//    Steps 1-2 repeat (cyclic coordinate ascent) until a cycle changes nothing, at most `cycles`.
// 3. Joint step (`joint`): in v = (log k, log f, log nu0) (the coordinates tuned for the rules in
//    use), a design around the cyclic choice (centre, star and 2-level factorial at one grid step
//    per coordinate, moved inward so k stays in [k_min, k_max]; halved in each of
//    `joint_rounds` rounds, each re-centred on the current choice) is evaluated; Ceres fits a full
//    concave quadratic q(v) (Hessian -L L^T, tune/quadratic_surrogate.h) to every cached
//    evaluation in the design's box, scaled by the best's standard error, and maximises it inside
//    that box; L is evaluated at the maximiser. The choice moves only when an evaluation of the
//    joint step beats the cyclic choice by more than the plateau tolerance; otherwise the cyclic
//    choice is kept (unless the plateau holds a strictly simpler equivalent model), and the report
//    says which.
//
// Plateaus (issue #10): in every step the evaluations within `plateau_tolerance` (default: one
// standard error of the best) of the best are equivalent; when there are several, L has a
// plateau: its range (of k, and in the joint step of f and nu0 too) is reported and the simplest
// model there (fewest mean Gaussians per command; ties: the higher L) is chosen instead of the
// maximum. The report always says so.
#include <functional>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "tune/cross_validation.h"

namespace dgmm {

struct TuneKOptions {
  // Folds, repeats, seed, threads, DGMM settings (dgmm.k is ignored); the EM baseline is off.
  CvOptions cv;
  bool with_terrain = true;  // maximise L for p(x | c, z) (or p(x | c) when false / no terrain)
  double k_min = 1e-3;       // coarse grid: grid_points values geometric in [k_min, k_max]
  double k_max = 10.0;
  int grid_points = 9;
  int refine_points = 4;  // extra evaluations strictly inside the bracket
  // Equivalence tolerance of the plateau rule in nats of L; 0: one standard error of the best.
  double plateau_tolerance = 0;
  // Grids for the coordinate steps after k; an empty grid (or a rule it does not apply to)
  // skips the step and keeps cv.dgmm's value.
  std::vector<double> init_scales = {0.03, 0.1, 0.3, 1.0, 3.0, 10.0};
  std::vector<double> prior_counts = {1.0, 4.0, 16.0, 64.0};
  int cycles = 3;        // at most this many (k, f, nu0) cycles
  bool joint = true;     // the joint Ceres step after the cycles (see above)
  int joint_rounds = 2;  // its rounds, each re-centred on the choice with half the step
  // Called before each cross-validation with (index, -1) (the total is not known in advance),
  // and once at the end with (total, total).
  std::function<void(int, int)> progress;
  bool IsValid(std::string* error) const;
};

// One evaluation of the curve.
struct TuneKPoint {
  double k = 0;
  double log_likelihood = 0;  // mean over repeats of the held-out total
  double sd = 0;              // over repeats
  double standard_error = 0;  // CvScore::standard_error
  std::string role;           // "grid", "refine", "chosen", "scale" or "prior"
  double components = 0;      // mean Gaussians per command and fold
  double init_scale = 0;      // f of this evaluation
  double prior_count = 0;     // nu0 of this evaluation
};

// Mean Gaussians per command closer than this count as the same model size in the plateau rule
// (a size is a mean over commands and folds; 0.01 is one Gaussian in a hundred command-folds).
constexpr double kSameModelSize = 0.01;

// The evaluations equivalent to the best (L >= L_best - tolerance) among `points`.
struct Plateau {
  std::vector<int> members;   // indices into points
  int best = -1;              // highest L
  // Among members within kSameModelSize of the fewest mean Gaussians per command, the highest L.
  int simplest = -1;
  bool flat = false;          // more than one member
  double k_lo = 0, k_hi = 0;  // range of k over the members
  double init_scale_lo = 0, init_scale_hi = 0, prior_count_lo = 0, prior_count_hi = 0;
};
Plateau FindPlateau(const std::vector<TuneKPoint>& points, double tolerance);

// The joint step (3. above): where it started, what the surrogate predicted, what was evaluated.
struct TuneJointStep {
  bool run = false;
  std::vector<std::string> coordinates;  // "log k", "log f", "log nu0": those tuned jointly
  TuneKPoint start;                      // the cyclic choice
  int rounds = 0;
  // The last round's surrogate maximiser in its box, its value q(v*), and L cross-validated there.
  double surrogate_k = 0, surrogate_init_scale = 0, surrogate_prior_count = 0;
  double surrogate_maximum = 0;
  double evaluated_log_likelihood = 0, evaluated_standard_error = 0;
  bool accepted = false;           // an evaluation beat the choice by more than the tolerance
  std::string rule;                // what each round did, one sentence per round
  int evaluations = 0;             // new cross-validations in this step
  int fit_points = 0;              // evaluations the surrogate was fitted to
  std::vector<TuneKPoint> points;  // every evaluation in the rounds' boxes and the maximisers'
  // Plateau over `points`: ranges of k, f and nu0 over the equivalent set.
  Plateau plateau;
  double tolerance = 0;
  std::string fit_report, maximise_report;  // Ceres BriefReport()s
};

struct TuneKSummary {
  double k = 0;               // the chosen merge rate
  double log_likelihood = 0;  // L(k), cross-validated at k
  double standard_error = 0;
  double sd = 0;
  bool with_terrain = true;
  // Bracket around the best grid point (k units).
  double bracket_lo = 0, bracket_hi = 0;
  // The fitted smooth curve q(u) = a + b (u - u0) + c (u - u0)^2, u = log k, c < 0, and its
  // maximiser over the bracket (the quadratic refinement; k is it unless the plateau rule chose).
  double u0 = 0, a = 0, b = 0, c = 0;
  int fit_points = 0;
  double quadratic_k = 0;
  double k_min = 0, k_max = 0;  // the coarse grid's ends
  double best_grid_k = 0;       // the best point of the last coarse grid
  // Where the chosen k sits: "low" or "high" when at (within 1e-9 of) an end of the grid or when
  // the best grid point is that end, else "" (the optimum may lie beyond the grid).
  std::string grid_edge;
  double Smoothed(double k) const;
  // Best evaluation of all (grid, refine, chosen).
  double best_evaluated_k = 0, best_evaluated_log_likelihood = 0;
  // The plateau of L(k) (see above): when flat, k is its simplest member, not the quadratic's.
  bool plateau = false;
  double plateau_k_lo = 0, plateau_k_hi = 0, plateau_tolerance = 0;
  int plateau_points = 0;
  std::string k_rule;  // how k was chosen, one sentence
  // True when the plateau reaches both ends of the grid: the data cannot tell k apart.
  bool plateau_spans_grid = false;
  bool plateau_tolerance_is_se = true;  // the tolerance is one standard error (the default)
  // What the plateau means, one sentence ("" without one), e.g. "k not identifiable from this data,
  // smallest model within 1 SE chosen".
  std::string PlateauMeaning() const;
  // The coordinate steps: chosen f and nu0 (0 when not tuned) and whether each was a plateau.
  double init_scale = 0, prior_count = 0;
  bool init_scale_tuned = false, prior_count_tuned = false;
  bool init_scale_plateau = false, prior_count_plateau = false;
  double components = 0;  // mean Gaussians per command at the chosen settings
  std::vector<TuneKPoint> scale_curve, prior_curve;
  std::vector<TuneKPoint> curve;            // the last k step's evaluations, ascending k
  TuneJointStep joint;                      // run when options.joint
  std::string fit_report, maximise_report;  // Ceres BriefReport()s
  int folds = 0, repeats = 0, samples = 0;
  int evaluations = 0, cycles = 0;  // distinct cross-validations; coordinate cycles run
  std::string folds_by;             // CvSummary::folds_by
  double seconds = 0;
  std::string BriefReport() const;
};

// Throws InputError for invalid options or an empty/inconsistent set.
TuneKSummary TuneK(const SampleSet& set, const TuneKOptions& options);

// The smoothing and maximisation steps alone (exposed for tests): fits q to (log k_j, L_j) near
// the best of the points and maximises it over [bracket_lo, bracket_hi] (k units). scale > 0
// divides the residuals (the standard error). Fills the fit fields and k of *summary.
void FitAndMaximise(const std::vector<TuneKPoint>& points, double bracket_lo, double bracket_hi,
                    double scale, TuneKSummary* summary);

}  // namespace dgmm
