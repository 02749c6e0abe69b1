#pragma once
// How a robot's deviations from its model persist from one command to the next (a heading error
// that lingers for several commands, say), so that predictions over many commands spread as much
// as the robot does. Each step of a prediction draws x = mu_k + L_k eps from p(x | c, z); with
// persistence the standard normal eps of consecutive steps are correlated, per dimension, as a
// persistent part and a fresh one:
//   eps_t = sqrt(a) u_t + sqrt(1 - a) w_t,   u_t = phi u_{t-1} + sqrt(1 - phi^2) v_t,
// so that corr(eps_t, eps_{t+l}) = a phi^l and every step on its own is still the model's
// p(x | c, z). (a, phi) are fitted to the lag correlations of the standardised residuals of
// recorded episodes. A robot that starts from standing moves more repeatably in its first
// command than the model's average over all steps: eps_1 is scaled by s, the RMS of the
// standardised residuals of the episodes' first steps.
#include <Eigen/Core>
#include <string>

#include "core/motion_model.h"
#include "core/sample_set.h"

namespace dgmm::predict {

struct StepPersistence {
  Eigen::VectorXd shared;  // a per pose dimension: the share of a deviation that persists, 0..1
  Eigen::VectorXd decay;   // phi per pose dimension: how much of it carries to the next step, 0..1
  // s per pose dimension: the first command's deviations from standing, relative to the model's
  // (empty: 1, the model's own spread).
  Eigen::VectorXd first_scale;
  bool empty() const { return shared.size() == 0; }
  // shared and decay of one size, every value in [0, 1]; first_scale empty or of that size, in (0, 10].
  bool IsValid(std::string* error) const;
};

struct PersistenceOptions {
  int max_lag = 5;     // lag correlations fitted: 1 .. max_lag steps apart
  int min_pairs = 30;  // a lag with fewer pairs of steps is left out of the fit (and first
                       // steps: fewer leave the first step at the model's spread)
};

struct PersistenceSummary {
  StepPersistence persistence;
  Eigen::MatrixXd lag_correlation;  // pose_dim x max_lag (NaN: too few pairs)
  Eigen::VectorXi pairs;            // pairs of steps per lag
  int episodes = 0;                 // episodes with at least two steps
  int first_steps = 0;              // samples that are the first step of their episode
  // RMS of the standardised residuals per pose dimension over all samples: near 1 when the model
  // describes the set; far from it, the set is not what the model was learnt from.
  Eigen::VectorXd residual_rms;
};

// Residual of each sample standardised under the most responsible component of the model's
// p(x | c, z): eps = L_k^-1 (x - mu_k); lag-l correlation of eps_d over steps l apart within an
// episode; (a, phi) minimise sum_l (rho_l - a phi^l)^2 over phi on a 0.01 grid in [0, 0.99], a
// in closed form clamped to [0, 1]; s_d = sqrt(mean eps_d^2) over first steps (step 0), within
// [0.1, 10]. The set must be raw (not standardised) and record episodes
// and steps (e.g. `dgmm simulate --protocol trajectories`); InputError naming the part otherwise.
// `source` names the set in errors (its file, say).
PersistenceSummary EstimatePersistence(const MotionModel& model, const SampleSet& set,
                                       const PersistenceOptions& options = {},
                                       const std::string& source = "sample set");

}  // namespace dgmm::predict
