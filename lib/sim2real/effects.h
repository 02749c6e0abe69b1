#pragma once
// A candidate of the analysis as the fits see it: a small parametric correction of the sim
// model's predictive distribution p_sim(x | c, z, prev) = N(u, Sigma):
//   mean u -> u + D_e(c, z, first) theta_e   (D_e: dx x p_e, supplied per sample by the
//                                             candidates stage: a knob's simulated signature, a
//                                             measurement effect's design; knob_design.h),
//   covariance Sigma -> tau^2 Sigma          (the noise effect, one parameter log tau).
#include <string>
#include <vector>

namespace dgmm::sim2real {

enum class EffectId {
  kNoise,     // real spread larger than simulated: Sigma * tau^2
  kExternal,  // a mean-shift design supplied per sample (knob signatures, measurement effects)
};

struct EffectParameter {
  std::string name;  // e.g. "t0"
  std::string unit;  // e.g. "fraction of the probe's change"
};

struct EffectSpec {
  EffectId id = EffectId::kExternal;
  std::string key;    // stable identifier used in report.json, e.g. "floor.friction.sliding@0.6"
  std::string title;  // e.g. "floor.friction.sliding (simulated)"
  std::vector<EffectParameter> parameters;
  bool is_noise = false;
  int num_params() const { return static_cast<int>(parameters.size()); }
};

// The noise effect (one parameter, log tau).
EffectSpec NoiseEffect();

}  // namespace dgmm::sim2real
