#pragma once
// Re-simulation with a fitted effect mapped onto a simulator parameter (--sim-config): when slip
// or stride loss is found, the slope's sliding friction is scanned over a few values, each
// re-simulated set trains a sim model, and the friction whose model explains the real set best
// (mean log-likelihood per real sample) is reported beside the nominal one.
#include <cstdint>
#include <string>

#include "core/sample_set.h"
#include "sim2real/pipeline.h"

namespace dgmm::sim2real {

struct RecalibrationOptions {
  std::string sim_config_path;
  std::uint64_t seed = 1;
  int placements = 40;  // per re-simulation (protocol paper-830: random headings, 5 executions)
  bool IsValid(std::string* error) const;
};

// JSON object text: {"parameter", "nominal", "candidates": [{"value", "mean_log_likelihood"}],
// "best", "improvement"} or {"skipped": reason}. Never throws for a missing simulator.
std::string Recalibrate(const Sim2RealResult& result, const SampleSet& real,
                        const RecalibrationOptions& options);

}  // namespace dgmm::sim2real
