#pragma once
// Does the gait walk the robot as it commands? For each pure command of a recording (one non-zero
// component c of (long, lat, turn)) the mean pose change of its executions against the gait's:
//   ratio = mean(dx_k) / (c * stride * cycles)  (k = long, lat),  mean(dyaw) / (c * turn * cycles)
// with cycles = command duration / gait period. A gait that moves the robot less than half or
// more than one and a half times what it commands (a ratio below 0.5 covers the wrong way) is far
// from its own command, and the protocol says so (the ratios scripts/walk_table.py tables).
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/sim_config.h"

namespace dgmm::sim {

// What one execution of |command| = 1 commands: travel (m), yaw (rad) per cycle and cycles.
struct CommandedWalk {
  double stride_m = 0;
  double turn_rad = 0;
  double cycles = 0;
};

// The generic gait's command (its stride relative to `leg_reach_m` unless given in metres);
// zero cycles (nothing commanded) for a robot without a robot block or driven by a replay.
CommandedWalk CommandedWalkOf(const SimConfig& config, double leg_reach_m);

struct WalkRatio {
  std::string command;  // "long +0.5", "lat -0.5", "turn +0.5"
  double ratio = 0;     // measured / commanded (1: as commanded)
  double commanded = 0; // per execution, in `unit`
  std::string unit;     // "m" (long, lat) or "rad" (turn)
};

// The ratio of every pure command with samples, in the set's command order (none when the set's
// commands are not (long, lat, turn) or `want` commands nothing).
std::vector<WalkRatio> WalkRatios(const SampleSet& set, const CommandedWalk& want);

// One line naming the commands whose ratio lies outside [lo, hi] (empty: none).
struct WalkBand {
  double lo = 0.5, hi = 1.5;
};
std::string WalkWarning(const std::vector<WalkRatio>& ratios, const WalkBand& band = {});

// A tracker whose position noise (sd, m) exceeds `share` of what a half command (the protocol's)
// moves the robot in one execution, 0.5 stride cycles: one line naming both (empty otherwise or
// when nothing is commanded). The noise is a length of the tracker's, not of the robot's: the
// config's default 3 mm is 2.2% of the hexapod's travel and 8.9% of a copy of it a quarter of its
// size (docs/simulation.md, "One robot at three sizes": the friction named 38% high there came from
// recordings whose noise stopped pairing after falls, since mended by ProtocolOptions::paired_streams).
inline constexpr double kTrackerNoiseShare = 0.05;
std::string TrackerNoiseWarning(double tracker_sd_m, const CommandedWalk& want, double share = kTrackerNoiseShare);

}  // namespace dgmm::sim
