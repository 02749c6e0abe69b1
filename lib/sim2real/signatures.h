#pragma once
// Signatures of the simulator's knobs (knob_simulator.h), learnt from the simulator itself: the
// sim set's own recording is repeated at the nominal knobs and at each knob probe with common
// random numbers (same placements, commands and sensor noise), and per command the paired
// difference x_probe - x_nominal is regressed on phi = (1, z, f), z the set's conditioning
// (pitch and roll; sensed terrain and continuous commands too when the set has them):
//   shift_k(c, z, f) = B_kc^T phi   (dx),  B_kc = (Phi^T Phi + Lambda)^-1 (Phi^T D + Lambda B_k,pool)
// with the slopes shrunk towards the slopes pooled over commands.
#include <Eigen/Dense>
#include <vector>

#include "core/sample_set.h"

namespace dgmm::sim2real {

// How x moves from a nominal simulated set to a paired perturbed one (per command, linear in
// phi = (1, z, f)); commands are the rows of `command_table_of` (the sim set's table,
// matched by label).
class PairedShift {
 public:
  // Throws InputError when fewer than 10 samples pair up.
  static PairedShift Fit(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& command_table_of,
                         double slope_ridge);
  // Mean shift (dx) at command c (row of the sim table), conditioning z, first flag.
  Eigen::VectorXd Shift(int command, const Eigen::Ref<const Eigen::VectorXd>& z, double first) const;
  // log(var_perturbed / var_nominal) per dimension of x: residuals about each command's linear
  // fit in phi (the spread the sim model's covariance describes), pooled over commands.
  const Eigen::VectorXd& log_variance_ratio() const { return log_var_; }
  // Per dimension of x: RMS over the pairs of x_probe - x_nominal, and the nominal's spread about each
  // command's linear fit in phi. Their ratio says how far apart paired executions walk (0: the probe
  // moved nothing; sqrt 2: paired executions as unrelated as two draws, walk_chance.h).
  const Eigen::VectorXd& paired_rms() const { return paired_rms_; }
  const Eigen::VectorXd& nominal_sd() const { return nominal_sd_; }
  int pairs() const { return pairs_; }

 private:
  std::vector<Eigen::MatrixXd> b_;  // per sim command: phi x dx (empty: not simulated, use pooled)
  Eigen::MatrixXd pooled_;          // phi x dx
  int phi_size_ = 4;                // 2 + max(2, conditioning dims)
  Eigen::VectorXd log_var_, paired_rms_, nominal_sd_;
  int pairs_ = 0;
};

}  // namespace dgmm::sim2real
