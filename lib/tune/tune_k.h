#pragma once
// Choice of the DGMM merge rate k (t = 1 - (1 - d) exp(-k n)) by cross-validated held-out
// log-likelihood L(k) (tune/cross_validation.h), with Ceres.
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
  // Called before each cross-validation with (index, planned total) of evaluations.
  std::function<void(int, int)> progress;
  bool IsValid(std::string* error) const;
};

// One evaluation of the curve.
struct TuneKPoint {
  double k = 0;
  double log_likelihood = 0;  // mean over repeats of the held-out total
  double sd = 0;              // over repeats
  double standard_error = 0;  // CvScore::standard_error
  std::string role;           // "grid", "refine" or "chosen"
};

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
  std::vector<TuneKPoint> curve;            // every evaluation, ascending k
  std::string fit_report, maximise_report;  // Ceres BriefReport()s
  int folds = 0, repeats = 0, samples = 0;
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
