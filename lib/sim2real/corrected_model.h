#pragma once
// The models of the analysis as MotionModel files that `dgmm score` and `dgmm render` read.
// Per command c a mixture over y = x || z whose conditional p(x | c, z) (eqs. 15-19) carries the
// analysis' prediction piecewise:
//   p(x | c, z) = sum_{k,f} w_ckf N(z; m_k, S_k) N(x; a_ckf + B_ckf (z - m_k), Sigma_ckf) / norm,
// with k the terrain pieces (k-means of the sim terrain samples, m_k, S_k their mean and
// covariance), f in {first execution, repeat} weighted by the real share of first executions
// (a model file has no sequence input), a + B (z - m_k) the local least-squares fit of the
// prediction E[x | c, z, f] = u_c(z, f) [+ sum_e D_e(c, z, f) theta_e] over the piece's
// samples, and Sigma_ckf = tau^2 Sigma_c(z, f) averaged over the piece plus the fit's residual
// scatter. See docs/sim2real.md, "The corrected model file".
#include <cstdint>
#include <string>

#include "core/motion_model.h"
#include "core/sample_set.h"
#include "sim2real/correction.h"
#include "sim2real/linear_gaussian.h"

namespace dgmm::sim2real {

struct CorrectedModelOptions {
  // Terrain pieces: about one per `samples_per_piece` sim samples, at most `max_pieces`.
  // 32 x 26 keeps the file's score within ~0.04 nats of the flag-mixed analysis on 830 samples.
  int max_pieces = 32;
  int samples_per_piece = 20;
  // At most this many of a piece's samples enter its local fit (evenly strided).
  int max_fit_points = 200;
  // Pseudo-count of sim samples added to every (command, piece) weight, so that a command whose
  // sim samples miss a piece still predicts there (from its local fit) instead of extrapolating.
  double piece_pseudo_count = 0.5;
  std::uint64_t seed = 1;  // k-means++ seeding of the pieces
  bool IsValid(std::string* error) const;
};

// kind "sim2real-sim": the sim-trained linear-Gaussian model used by the analysis; first
// executions mixed in with the real set's share. `sim` is the sim set in raw units.
MotionModel BuildSimModel(const LinearGaussianModel& model, double first_execution_share, const SampleSet& sim,
                          const CorrectedModelOptions& options = {});
// kind "corrected": the sim model moved by the knob correction (correction.h).
MotionModel BuildCorrectedModel(const LinearGaussianModel& model, const Correction& correction,
                                double first_execution_share, const SampleSet& sim,
                                const CorrectedModelOptions& options = {});

}  // namespace dgmm::sim2real
