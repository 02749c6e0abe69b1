#include "sim2real/effects.h"

namespace dgmm::sim2real {

EffectSpec NoiseEffect() {
  EffectSpec e;
  e.id = EffectId::kNoise;
  e.key = "tracker_noise";
  e.title = "Real spread larger than simulated (scale of the sim covariance)";
  e.parameters = {{"log_tau", "log of the scale of the sim model's standard deviations"}};
  e.is_noise = true;
  return e;
}

}  // namespace dgmm::sim2real
