#pragma once
// The paper's recording protocol (Edgington et al. 2009, section VI-B) run in simulation:
// commands {-0.5, 0, 0.5}^3 without the no-op (26), each run 5 times in a row per placement on
// the slope; x = change of pose in the body frame, z = <pitch, roll> from the IMU before.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"

namespace dgmm::sim {

enum class Protocol {
  // 26 commands drawn without replacement, one placement each per heading 0, +90, -90 deg
  // (cycling), 5 executions: 26 * 3 * 5 = 390 samples.
  kPaper,
  // 166 placements at uniformly random heading and position on the slope, commands cycling
  // through seeded shuffles of the 26, 5 executions: 830 samples.
  kPaper830,
  // Multi-command trajectories, for checking predictions (docs/prediction.md): 100 placements at
  // uniformly random heading and position, each running a sequence of executions_per_placement
  // commands drawn uniformly (with replacement) from the 26; episode = placement, step = its index.
  kTrajectories,
  // Continuous commands (issue #25): 166 placements at uniformly random heading and position,
  // each running executions_per_placement commands drawn uniformly from [-0.5, 0.5]^3 (long,
  // lat, turn); one command-table row "velocity", and the command values stored as the first
  // three conditioning dimensions of z (cmd_long, cmd_lat, cmd_turn, then pitch, roll), so that
  // models give p(x | command, z) for any command in the range.
  kContinuous,
};

// "paper" / "paper-830" / "trajectories" / "continuous"; ParseProtocol throws InputError for
// anything else.
std::string ProtocolName(Protocol protocol);
Protocol ParseProtocol(const std::string& name);

struct ProtocolOptions {
  Protocol protocol = Protocol::kPaper;
  std::uint64_t seed = 0;
  int executions_per_placement = 5;
  // 0: the protocol's default number of placements (78 or 166); otherwise that many (for tests).
  int placements = 0;
  // A placement whose robot falls or flips is discarded and re-placed up to this many times.
  int max_retries_per_placement = 3;
  // 0: every placement on one simulator, retries and sensor noise from the seed's one stream (how
  // the shipped sets were made). > 0: the placements in fixed chunks of this many, each on its own
  // simulator with its own stream (from the seed and the chunk's index), run on up to `threads`
  // threads: the set depends on the chunk size, not on the thread count.
  int chunk_placements = 0;
  int threads = 1;
  // false: a fall's retries draw their spot and sensor noise from the recording's stream, so every
  // later placement's noise shifts (how the shipped sets were made). true: retries draw from
  // streams of their own (seed, placement, attempt) and the recording's stream moves on as if the
  // placement had held, so recordings of one plan at different knob values share each placement's
  // noise whatever falls in either (sim2real's paired signatures); a recording without falls is
  // the same either way.
  bool paired_streams = false;

  bool IsValid(std::string* error) const;
};

// A torso tilted beyond this from the ground's plane at the start of an execution walks another
// robot than the one the commands were meant for; the protocol counts those executions and warns.
inline constexpr double kTiltedDeg = 25;
// The torso's up axis more than kTiltedDeg from the ground's normal: cos(angle) = R(2, 2).
bool TiltedBeyondThreshold(const Pose& torso_in_ground);

struct SimSummary {
  int samples = 0;
  int placements = 0;
  int falls = 0;                 // falls/flips detected (each discarded its placement)
  int abandoned_placements = 0;  // placements given up after max_retries_per_placement falls
  double simulated_seconds = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;  // process CPU time while simulating (wall time suffers on a busy machine)
  int executions = 0;               // commands run (fallen ones included)
  int self_contact_executions = 0;  // of which the robot touched itself (Simulator::SelfContactSteps)
  int tilted_executions = 0;        // of which the torso started tilted beyond kTiltedDeg from the ground's plane
  // The config against the robot (Simulator::RobotWarnings) and the robot touching itself.
  std::vector<std::string> warnings;

  double SimulatedPerWallSecond() const;
  double SamplesPerWallSecond() const;
  std::string BriefReport() const;
  // The torso started tilted in more than a twentieth of the executions: the protocol warns.
  bool TiltedTooOften() const { return tilted_executions * 20 > executions; }
};

// Progress callback: (placements done, placements total).
using ProgressFn = std::function<void(long long done, long long total)>;

// Runs the protocol; same config, options and seed give the same set. The set carries the
// command table (long, lat, turn), x (dx, dy, dz [m]; droll, dpitch, dyaw [rad]), z (pitch, roll
// [rad]), episode = placement, step = execution index, source "sim", metadata (config JSON,
// protocol, seed, falls). Throws InputError for an invalid config/options or unloadable MJCF.
// `edit` changes the compiled model after the config (lib/sim/knobs.h); the same seed draws the
// same placements and sensor noise, so two runs differing only in physics are paired.
SampleSet SimulateProtocol(const SimConfig& config, const ProtocolOptions& options,
                           const ProgressFn& progress = {}, SimSummary* summary = nullptr,
                           const ModelEdit& edit = {});


// One command x terrain cell of a discriminating experiment (docs/sim2real.md, "The experiment
// check"): `placements` placements at seeded random positions on the slope, all at one heading,
// each repeating `command` executions_per_placement times.
struct CellOptions {
  Eigen::Vector3d command = Eigen::Vector3d::Zero();  // (long, lat, turn)
  double heading_rad = 0;  // slope frame, 0 = facing uphill
  // One heading per placement (e.g. HeadingsForTerrain on rough ground); empty: heading_rad for all.
  std::vector<double> headings_rad;
  int placements = 4;
  int executions_per_placement = 5;
  std::uint64_t seed = 0;
  int max_retries_per_placement = 3;  // as ProtocolOptions'
  // As ProtocolOptions': true pairs two cells' sensor noise placement by placement whatever falls
  // in either (sim2real's experiment check compares cells at two knob values).
  bool paired_streams = false;
};

// Runs one cell; the same options and seed draw the same positions and sensor noise, so two runs
// differing only in physics (`edit`, the config) are paired. The set has the protocol's command
// table (or a one-row table when `command` is not one of its rows) and metadata protocol "cell".
// Throws InputError for an invalid config or options.
SampleSet SimulateCell(const SimConfig& config, const CellOptions& cell, SimSummary* summary = nullptr,
                       const ModelEdit& edit = {});

// The heading (slope frame) whose settled standing pose has the IMU (pitch, roll) closest to the
// given one, among `headings` evenly spaced headings (the robot placed at the slope's centre).
double HeadingForTerrain(const SimConfig& config, double pitch_rad, double roll_rad, int headings = 24,
                         const ModelEdit& edit = {});
// The same search at each of the cell's placement positions (those SimulateCell draws from
// cell.seed): on rough ground the IMU's pitch and roll depend on where the robot stands as well as
// on its heading. Returns one heading per placement.
std::vector<double> HeadingsForTerrain(const SimConfig& config, const CellOptions& cell, double pitch_rad,
                                       double roll_rad, int headings = 24);

}  // namespace dgmm::sim
