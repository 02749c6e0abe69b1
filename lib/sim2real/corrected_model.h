#pragma once
// The models of the analysis as MotionModel files that `dgmm score` and `dgmm render` read:
// per command one joint Gaussian over y = x || z (a one-component mixture) whose conditional
// p(x | c, z) is the linear-Gaussian prediction. The corrected model adds the fitted effects:
//   E[x | c, z] = u_c(z) + sum_e D_e(u_c(z), g(z), first) theta_e,  Cov = tau^2 Sigma_c.
// Approximations (docs/sim2real.md): effects that are non-linear in z (through sin of pitch and
// roll) are projected by least squares onto a linear function of z over the command's terrain
// range; sequence effects are averaged with the real share of first executions; the predictive
// inflation of the covariance is taken at the command's mean terrain.
#include "core/motion_model.h"
#include "core/sample_set.h"
#include "sim2real/pipeline.h"

namespace dgmm::sim2real {

// kind "sim2real-sim": the sim-trained linear-Gaussian model used by the analysis.
MotionModel BuildSimModel(const Sim2RealResult& result, const SampleSet& sim);
// kind "corrected": the sim model plus the fitted effects.
MotionModel BuildCorrectedModel(const Sim2RealResult& result, const SampleSet& sim);

}  // namespace dgmm::sim2real
