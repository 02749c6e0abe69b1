#pragma once
// Maximum-likelihood fit of a set of effects to real data under the corrected sim model
//   x_i ~ N(u_i + sum_e D_e,i theta_e, tau^2 S Sigma_i S),  S = diag(exp(s / 2)),
// with Ceres (GradientProblem, L-BFGS) on the whitened form: with L_i L_i^T = Sigma_i,
//   -log p = sum_i [ 1/2 tau^-2 |L_i^-1 S^-1 (x_i - u_i - D_i theta)|^2 + dx log tau + 1/2 sum s ] + const.
// s = sum_e theta_e,0 v_e (per axis, clamped to +-max_log_ratio) for effects that carry a spread
// signature v_e (a knob's simulated log-variance ratio, signatures.h); without any, S = I.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "sim2real/effects.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

// Everything the fits need, precomputed once for the real samples under the sim model.
struct FitProblem {
  int n = 0, dx = 0;
  std::vector<EffectSpec> library;
  Eigen::MatrixXd r0;               // n x dx whitened residuals under the sim model
  Eigen::VectorXd log_norm;         // n: -1/2 (dx log 2 pi + log det Sigma_i)
  std::vector<Eigen::MatrixXd> chol;  // n: lower Cholesky factor L_i of Sigma_i (dx x dx)
  std::vector<Eigen::MatrixXd> g;   // per library effect: (n dx) x p_e whitened designs
  std::vector<Eigen::MatrixXd> d;   // per library effect: (n dx) x p_e raw mean-shift designs
  std::vector<int> episode;         // for grouped folds and the bootstrap
  std::vector<int> command;
  Eigen::MatrixXd raw;              // n x dx raw residuals x_i - u_i (= L_i r0_i)
  // Per library effect: the log-variance ratio per axis that its first parameter scales (empty:
  // the effect leaves the spread alone, the default for every effect).
  std::vector<Eigen::VectorXd> log_var;
  double max_log_ratio = 2.0;       // |s| per axis at most (no wild extrapolation)
};

// The designs start at zero: SetDesign fills each mean effect's rows.
FitProblem MakeFitProblem(const Samples& real, const LinearGaussianModel& sim_model,
                          const std::vector<EffectSpec>& library);
// Row i of effect k: raw design d (dx x p_k) and its whitened form L_i^-1 d.
void SetDesign(FitProblem* fp, int k, int i, const Eigen::MatrixXd& d);

// Fitted parameters of a set of library effects (indices into FitProblem::library).
struct EffectFit {
  std::vector<int> effects;
  std::vector<Eigen::VectorXd> theta;  // per entry of `effects` (the noise effect: log tau)
  double log_tau = 0;                  // 0 unless the noise effect is in the set
  Eigen::VectorXd log_var;             // s (dx), empty unless a fitted effect carries a spread signature
  double train_log_likelihood = 0;     // total over the training rows
  bool converged = false;
  int iterations = 0;
};

struct EffectFitOptions {
  int max_iterations = 300;
  double ridge = 1e-6;  // on the column-scaled parameters, keeps collinear designs solvable
  bool IsValid(std::string* error) const;
};

// ML fit on `rows` (all when empty).
EffectFit FitEffects(const FitProblem& problem, const std::vector<int>& effects,
                     const std::vector<int>& rows, const EffectFitOptions& options = {});

// log p(x_i) under the corrected model for each listed row (all when empty).
Eigen::VectorXd CorrectedLogLikelihood(const FitProblem& problem, const EffectFit& fit,
                                       const std::vector<int>& rows = {});

// Whitened mean shift (n dx) of one fitted effect entry k of `fit` (for comparing effects).
Eigen::VectorXd WhitenedShift(const FitProblem& problem, const EffectFit& fit, int k);

}  // namespace dgmm::sim2real
