#include "app/wiring/mujoco_knob_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/compiled_model.h"
#include "sim/replay.h"
#include "sim/protocol.h"
#include "sim/simulator.h"
#include "sim2real/simulation_cache.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

// Bump when a change of lib/sim changes what a recording at the same inputs contains (v2: the key
// covers the compiled model, not the top-level MJCF text; v3: the generic gait solves every
// leg's inverse kinematics in one pass).
constexpr const char* kSimulatorCodeVersion = "dgmm-mujoco-sim-v11";
// v6: a recording runs in chunks of this many placements, each with its own random stream, so
// one recording can use several threads (sim::ProtocolOptions::chunk_placements). v7: a servo
// gets the ctrl that holds its joint at the target (through its gear) and the gait keeps within
// its ctrlrange, a site, body or visual-geom foot is placed by its body's colliding geoms and a
// mesh foot by its lowest vertex (recordings of robots with geared or ctrl-limited servos or such
// feet changed; others not).
// v8: a payload on a torso compiled with its centre of mass at its origin (MuJoCo's body_sameframe:
// the hexapod, the planar quadruped, the scorpion and harvestman shapes with a robot block) moves
// the centre MuJoCo simulates; before, only its mass and inertia acted (recordings of payloads off
// the middle on such robots changed; others not).
// v9: a payload merged into a torso whose principal axes are turned (the sprawled and mammal-shaped
// quadrupeds') or placed off the torso's axes adds its inertia in the torso's principal frame,
// products of inertia included; before, its parallel-axis terms were added per axis of the body's
// frame to the moments of the principal frame (such recordings changed; the hexapod's, planar
// quadruped's and octopod's not).
// v10: the generic gait solves its targets at least 60 times a cycle (generic_walker.h,
// ControlEvery; before, at 100 Hz whatever the cycle): recordings of gaits whose cycle is under
// 0.6 s changed (the scorpion's robot block), others not.
// v11: recordings pair their sensor noise placement by placement whatever falls
// (sim::ProtocolOptions::paired_streams): recordings with a fall changed, others not.
constexpr int kChunkPlacements = 13;

sim2real::Knob::Role RoleOf(sim::KnobKind kind) {
  switch (kind) {
    case sim::KnobKind::kPayloadMass: return sim2real::Knob::Role::kPayloadMass;
    case sim::KnobKind::kPayloadX: return sim2real::Knob::Role::kPayloadX;
    case sim::KnobKind::kPayloadY: return sim2real::Knob::Role::kPayloadY;
    case sim::KnobKind::kTrackerNoiseScale: return sim2real::Knob::Role::kSpread;
    default: return sim2real::Knob::Role::kShift;
  }
}

sim2real::Knob FromSim(const sim::Knob& k) {
  sim2real::Knob out;
  out.name = k.name;
  out.family = k.family;
  out.unit = k.unit;
  out.role = RoleOf(k.kind);
  out.nominal = k.nominal;
  out.lo = k.lo;
  out.hi = k.hi;
  out.probes = k.probes;
  // Offsets may have either sign; every other knob is a non-negative physical quantity.
  const bool offset = k.kind == sim::KnobKind::kPayloadX || k.kind == sim::KnobKind::kPayloadY;
  if (!offset) out.physical_min = 0;
  if (k.kind == sim::KnobKind::kLegGain) out.leg = k.leg;
  if (k.kind == sim::KnobKind::kSideGain) {
    out.side = k.index == 0 ? "left" : "right";
    out.members = k.members;
  }
  return out;
}

}  // namespace

MujocoKnobSimulator::MujocoKnobSimulator(const sim::SimConfig& config) : config_(config) {
  sim_knobs_ = sim::EnumerateKnobs(config_);
  for (const auto& k : sim_knobs_) knobs_.push_back(FromSim(k));
  // Everything that determines a recording besides protocol, seed and knobs (those are in the
  // recording key): the simulator's code version, the compiled model (included files, meshes and
  // height fields with it) and the config without its path, so moving the robot's folder hits.
  sim::SimConfig keyed = config_;
  keyed.mjcf_path.clear();
  if (keyed.robot) {
    for (auto& rec : keyed.robot->controller.recordings) rec.file.clear();  // their bytes are keyed instead
  }
  fingerprint_ = sim2real::HashHex(std::string(kSimulatorCodeVersion) + "\n" + sim::CompiledModelBytes(config_) +
                                   "\n" + sim::ReplayBytes(config_) + "\n" + sim::SimConfigToJson(keyed));
  const sim::Simulator robot(config_);
  total_mass_kg_ = robot.total_mass_kg();
  leg_reach_m_ = robot.leg_reach_m();
  level_ground_ = robot.LevelGround();
  plane_ground_ = robot.PlaneGround();
  sloped_ground_ = robot.SlopedGround();
}

std::vector<sim::KnobValue> MujocoKnobSimulator::ToSim(const std::vector<sim2real::KnobValue>& values) const {
  std::vector<sim::KnobValue> out;
  for (const auto& v : values) {
    if (v.knob < 0 || v.knob >= static_cast<int>(sim_knobs_.size())) {
      throw MakeInputError("simulator", "knob", "index " + std::to_string(v.knob) + " out of range");
    }
    out.push_back({v.knob, v.value});
  }
  return out;
}

SampleSet MujocoKnobSimulator::Record(const sim2real::Recording& recording,
                                      const std::vector<sim2real::KnobValue>& values, int threads) const {
  sim::ProtocolOptions options;
  options.chunk_placements = kChunkPlacements;
  options.paired_streams = true;  // a signature is a difference of two recordings: their noise pairs up
  options.threads = std::max(1, threads);
  options.protocol = sim::ParseProtocol(recording.protocol);
  options.seed = recording.seed;
  options.placements = recording.placements;
  if (recording.executions_per_placement > 0) options.executions_per_placement = recording.executions_per_placement;
  return sim::SimulateWithKnobs(config_, options, sim_knobs_, ToSim(values));
}

sim2real::CellRecording MujocoKnobSimulator::RecordCell(const sim2real::Cell& cell,
                                                        const std::vector<sim2real::KnobValue>& values) const {
  if (cell.command.size() != 3) {
    throw MakeInputError("experiment cell", "command", "expected (long, lat, turn)");
  }
  if (cell.terrain.size() != 2) {
    throw MakeInputError("experiment cell", "terrain", "expected (pitch, roll)");
  }
  sim2real::CellRecording out;
  const double heading = sim::HeadingForTerrain(config_, cell.terrain(0), cell.terrain(1));
  out.heading_deg = heading * 180.0 / M_PI;
  char where[96];
  std::snprintf(where, sizeof where, "heading %.0f deg on the %.3g deg slope", out.heading_deg, config_.slope_deg);
  out.placement = where;
  sim::CellOptions options;
  options.command = cell.command;
  options.heading_rad = heading;
  options.placements = cell.placements;
  options.executions_per_placement = cell.executions_per_placement;
  options.seed = cell.seed;
  options.paired_streams = true;  // as the recordings (v11): cells at two values pair their noise whatever falls
  if (config_.terrain) {  // rough ground: pitch and roll depend on the position too
    options.headings_rad = sim::HeadingsForTerrain(config_, options, cell.terrain(0), cell.terrain(1));
    std::snprintf(where, sizeof where, "headings matched per placement on the %.3g deg slope's rough ground",
                  config_.slope_deg);
    out.placement = where;
  }
  sim::ModelEdit edit;
  const sim::SimConfig c = sim::ApplyKnobs(config_, sim_knobs_, ToSim(values), &edit);
  out.set = sim::SimulateCell(c, options, nullptr, edit);
  return out;
}

std::string MujocoKnobSimulator::ConfigJson(const std::vector<sim2real::KnobValue>& values) const {
  sim::ModelEdit edit;  // knobs that edit the compiled model are not in the config (yet)
  return sim::SimConfigToJson(sim::ApplyKnobs(config_, sim_knobs_, ToSim(values), &edit));
}

}  // namespace dgmm::app
