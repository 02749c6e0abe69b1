#pragma once
// `dgmm tune` (alias tune-k): choice of the DGMM merge rate k, initial scale and prior strength (t
// = 1 - (1 - d) exp(-k n)) by cross-validated held-out log-likelihood L(k)
// (tune/cross_validation.h), with Ceres.
//
// L(k) is noisy and piecewise constant in k: a merge decision r < t flips only when k crosses a
// threshold. So (1) every k sees the same folds and random numbers (common random numbers: the
// CvOptions seed does not depend on k), which makes L(k) - L(k') a low-noise comparison;
// (2) L is evaluated on a coarse grid in u = log k and the best grid point brackets the optimum
// [u_{i-1}, u_{i+1}]; the bracket gets a few more evaluations; (3) Ceres fits a smooth concave
// quadratic q(u) = a + b (u - u0) - exp(g) (u - u0)^2 to the evaluations near the best by robust
// (Cauchy) least squares, scaled by the standard error; (4) Ceres' line-search solver maximises
// q over the bracket (u = lo + (hi - lo) sigmoid(s), unconstrained in s). L is then evaluated at
// the chosen k and reported with its standard error.
//
// Plateaus (issue #10): L(k) is often flat over a range of k (e.g. every k giving one Gaussian
// per command). The evaluations within `plateau_tolerance` (default: one standard error of the
// best) of the best are equivalent; when there are several, the curve has a plateau: its k
// range is reported and the simplest model there (fewest mean Gaussians per command; ties: the
// higher L) is chosen instead of the quadratic's maximum. The report always says so.
//
// Jointly with k, by cyclic coordinate ascent: after the k step, at the chosen k, grids over the
// initial covariance scale f (S0 = f v, for --init-cov data) and then the prior pseudo-count nu0
// (for the prior covariance rule), same plateau rule; the cycle (k, f, nu0) repeats until it
// changes nothing, at most `cycles` times. Each evaluation is a full cross-validation, cached.
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
  int cycles = 3;  // at most this many (k, f, nu0) cycles
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

// The evaluations equivalent to the best (L >= L_best - tolerance) among `points`.
struct Plateau {
  std::vector<int> members;   // indices into points
  int best = -1;              // highest L
  int simplest = -1;          // fewest components among members (ties: higher L)
  bool flat = false;          // more than one member
  double k_lo = 0, k_hi = 0;  // range of k over the members
};
Plateau FindPlateau(const std::vector<TuneKPoint>& points, double tolerance);

struct TuneKSummary {
  double k = 0;               // the chosen merge rate
  double log_likelihood = 0;  // L(k), cross-validated at k
  double standard_error = 0;
  double sd = 0;
  bool with_terrain = true;
  // Bracket around the best grid point (k units); at_grid_edge when it is the first or last.
  double bracket_lo = 0, bracket_hi = 0;
  bool at_grid_edge = false;
  // The fitted smooth curve q(u) = a + b (u - u0) + c (u - u0)^2, u = log k, c < 0.
  double u0 = 0, a = 0, b = 0, c = 0;
  int fit_points = 0;
  double Smoothed(double k) const;
  // Best evaluation of all (grid, refine, chosen).
  double best_evaluated_k = 0, best_evaluated_log_likelihood = 0;
  // The plateau of L(k) (see above): when flat, k is its simplest member, not the quadratic's.
  bool plateau = false;
  double plateau_k_lo = 0, plateau_k_hi = 0, plateau_tolerance = 0;
  int plateau_points = 0;
  std::string k_rule;  // how k was chosen, one sentence
  // The coordinate steps: chosen f and nu0 (0 when not tuned) and whether each was a plateau.
  double init_scale = 0, prior_count = 0;
  bool init_scale_tuned = false, prior_count_tuned = false;
  bool init_scale_plateau = false, prior_count_plateau = false;
  double components = 0;  // mean Gaussians per command at the chosen settings
  std::vector<TuneKPoint> scale_curve, prior_curve;
  std::vector<TuneKPoint> curve;            // the last k step's evaluations, ascending k
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
