#pragma once
// Who widens the real spread (docs/sim2real.md, "Spread: knobs or tracker noise"): after the
// mean-shift correction, the real residuals' covariance is the sim model's scaled per pose axis,
//   Sigma_i' = S Sigma_i S,  S = diag(sqrt(rho)),  rho = K + a T   (dx),
// with K = exp(sum_k theta_k v_k) the spread change the named knobs make in simulation (v_k: each
// knob's simulated log-variance ratio at its signature value, theta_k its fitted coefficient) and
// T = exp(v_t) - 1 the variance the tracker-noise probe adds, relative to the nominal spread, so
// that a = (s^2 - 1) / (s_probe^2 - 1) for a tracker-noise scale s. The tracker noise is needed
// only when a fitted a beats a = 0 on held-out real data.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "sim2real/effect_fit.h"

namespace dgmm::sim2real {

struct SpreadOptions {
  double z = 1.645;              // one-sided held-out z the tracker noise must beat (at least; the
                                 // knob analysis raises it to the noise's forward-step Bonferroni z)
  double min_gain_nats = 0.01;   // and its gain per real sample
  double max_log_ratio = 2.0;    // |sum_k theta_k v_k| per axis at most (no wild extrapolation)
  bool IsValid(std::string* error) const;
};

// Everything but the effects (the rows' Cholesky factors L_i come with the FitProblem).
struct SpreadProblem {
  const FitProblem* fit = nullptr;
  std::vector<Eigen::VectorXd> log_var;  // per library effect: v (dx), empty when it has none
  Eigen::VectorXd tracker;               // T (dx); empty: no tracker-noise knob
  double a_lo = -1, a_hi = 1;            // the tracker knob's range in a
};

// K (dx) of a fit: exp of the fitted effects' summed log-variance signatures, clamped.
Eigen::VectorXd KnobSpread(const SpreadProblem& sp, const EffectFit& fit, const SpreadOptions& options);

// log p(x_i) per listed row with the mean effects of `fit` and the per-axis variance ratio rho.
Eigen::VectorXd SpreadLogLikelihood(const SpreadProblem& sp, const EffectFit& fit, const Eigen::VectorXd& rho,
                                    const std::vector<int>& rows);

// The tracker coefficient a maximising the likelihood of `rows` given the mean effects of `fit`,
// its knobs' spread K and the tracker's T (golden section over the knob's range).
double FitTrackerCoefficient(const SpreadProblem& sp, const EffectFit& fit, const Eigen::VectorXd& k,
                             const Eigen::VectorXd& t, const std::vector<int>& rows);

struct SpreadTest {
  bool tested = false;
  Eigen::VectorXd knob_log_ratio;  // log K on all rows (dx)
  double a = 0;                    // tracker coefficient on all rows
  double gain = 0, se = 0, z = 0;  // held-out nats per real sample of rho = K + a T over rho = K
  bool tracker_needed = false;
};

// Cross-validated test (same folds as the selection) of the tracker noise beyond the spread the
// mean effects `effects` (library indices, no noise effect) make in simulation.
SpreadTest TestTrackerSpread(const SpreadProblem& sp, const std::vector<int>& effects, const std::vector<int>& rows,
                             const std::vector<int>& fold, const EffectFitOptions& fit_options,
                             const SpreadOptions& options);

}  // namespace dgmm::sim2real
