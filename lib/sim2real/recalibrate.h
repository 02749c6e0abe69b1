#pragma once
// Re-simulation with the selected effects mapped onto simulator parameters (--sim-config):
//   slope_slip, stride_loss, slope_traction -> friction.sliding (grid 1.0 .. 0.55 x nominal,
//                                               then the parabola's vertex);
//   payload_offset                          -> payload mass and position (three probes measure
//                                               the simulator's response, the payload is solved
//                                               from the fitted effect, then checked);
//   actuator_asymmetry                      -> actuators.leg_gain (each leg at half gain, then
//                                               the best leg's gain refined).
// Each candidate config is scored by ResimScorer (re-simulated shift projected on the selected
// effects, real log-likelihood per sample); the best of every scan are combined into one
// recalibrated config, which is checked directly: models trained on larger re-simulations of
// the nominal and the recalibrated config, scored on the real set.
#include <cstdint>
#include <string>

#include "core/sample_set.h"
#include "sim2real/pipeline.h"

namespace dgmm::sim2real {

struct RecalibrationOptions {
  std::string sim_config_path;
  std::uint64_t seed = 1;
  int placements = 40;         // per scan re-simulation (protocol paper-830, 5 executions)
  int verify_placements = 80;  // per set of the direct check (0: no check)
  int threads = 2;             // simulations run in parallel
  bool IsValid(std::string* error) const;
};

// JSON object text (see docs/sim2real.md, "Re-simulation"): "scans" (one per mapped effect:
// "effect", "parameter", "nominal", "candidates", "best", "improvement_nats_per_sample"), the
// friction scan's keys also at top level, "recalibrated_config", "verification"; or
// {"skipped": reason}. Never throws.
std::string Recalibrate(const Sim2RealResult& result, const SampleSet& real,
                        const RecalibrationOptions& options);

}  // namespace dgmm::sim2real
