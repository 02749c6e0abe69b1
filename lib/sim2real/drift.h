#pragma once
// Does a named effect stay constant over the session, or drift? A simulator knob is a constant:
// a servo that weakens as it heats, a tracker that drifts through the day, are not, and naming the
// average knob value as "the" physics would send the user to fix the wrong thing.
//
// With r_i the residual of the corrected model and s_i the effect's fitted shift (both whitened,
// n x dx, same units), t_i the recording position of sample i's episode in [0, 1] (episode ids in
// recording order) minus its sample-weighted mean, the drift of the effect's coefficient is
//   gamma = sum_i t_i <r_i, s_i> / sum_i t_i^2 |s_i|^2
// i.e. the effect's size goes from about (1 - gamma/2) of its fitted value in the first episodes
// to (1 + gamma/2) in the last. Its significance is a permutation test of |sum_i t_i <r_i, s_i>|:
// commands swap their (mean) positions as whole blocks and episodes shuffle their offsets within
// their command, so the unit of exchange is the command. This is valid when the protocol's command
// order is random (dgmm simulate's protocols are); a fixed order that always records, say, the
// turns last would confound a per-command error with a drift.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

namespace dgmm::sim2real {

struct DriftOptions {
  int permutations = 1000;
  double alpha = 0.01;             // family-wise over the effects tested (Bonferroni)
  // Smallest |gamma| called a drift: the effect changes by at least half its fitted size between
  // the first and the last episode (relative, so free of units).
  double min_relative_change = 0.5;
  bool IsValid(std::string* error) const;
};

struct EffectDrift {
  double gamma = 0;          // relative change of the coefficient from the first to the last episode
  double p_value = 1;
  double z = 0;              // (statistic - null mean) / null SD over the permutations
  bool drifting = false;     // set by the caller's family-wise level (see MarkDrifting)
  int episodes = 0;
  // Step variation only: relative size (1 + A_k / B_k) at the smallest and the largest step.
  double low = 1, high = 1;
  int low_step = -1, high_step = -1;
};

// `residual` and `shift` n x dx (whitened, same units); `command`, `episode` per sample. Returns
// gamma 0, p 1 when there are fewer than 2 episodes or the shift is zero.
EffectDrift TestEffectDrift(const Eigen::MatrixXd& residual, const Eigen::MatrixXd& shift,
                            const std::vector<int>& command, const std::vector<int>& episode,
                            const DriftOptions& options, std::uint64_t seed);

// Does the effect's size vary with the execution index within a placement (a step-periodic or
// step-dependent effect a constant only matches on average)? With A_k = sum_{i at step k} <r_i, s_i>
// and B_k = sum_{i at step k} |s_i|^2, Q = sum_k A_k^2 / B_k; the relative size of the effect at
// step k is 1 + A_k / B_k, and gamma = sqrt(max(0, Q - E0[Q]) / sum_k B_k) is their weighted RMS
// spread around 1 with the noise's share E0[Q] (the permutation mean) taken out. p: step labels
// permuted within each episode (as the residual step test). `low_step`/`high_step`: the steps
// with the smallest and the largest relative size. Steps < 0 (no sequence data): no test.
EffectDrift TestEffectStepVariation(const Eigen::MatrixXd& residual, const Eigen::MatrixXd& shift,
                                    const std::vector<int>& episode, const std::vector<int>& step,
                                    const DriftOptions& options, std::uint64_t seed);

// `total` is the test of the whole correction (the sum of the effects' shifts); it drifts when
// p < alpha and |gamma| >= min_relative_change. Each effect drifts when the whole correction does
// and its own p < alpha / size and |gamma| >= min_relative_change: the correction as a whole must
// change over the session before one of its parts is called a drift (one effect's test alone can
// pick up how two correlated effects share a constant mismatch differently over the session).
void MarkDrifting(EffectDrift* total, std::vector<EffectDrift>* drifts, const DriftOptions& options);

}  // namespace dgmm::sim2real
