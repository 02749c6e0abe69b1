#include "sim/protocol.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <initializer_list>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <vector>

#include "core/set_warnings.h"
#include "sim/pose.h"
#include "sim/replay.h"
#include "sim/simulator.h"
#include "sim/walk_check.h"
#include "util/error.h"
#include "util/parallel_for.h"

namespace dgmm::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One placement: where the robot stands, which command it repeats.
struct Placement {
  int command = 0;
  std::vector<int> sequence;  // kTrajectories: the command of each execution (else `command` repeats)
  std::vector<Eigen::Vector3d> values;  // kContinuous: the command of each execution
  double heading_rad = 0;  // slope frame, 0 = facing uphill
  double x_unit = 0, y_unit = 0;  // in [-1, 1]: times Simulator::placement_half_width_m()
};

std::string FormatLevel(double v) {
  if (v == 0) return "0";
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%+.1f", v);
  return buf;
}

// Protocol heading theta (0 = across the slope, +90 = looking downhill, -90 = uphill) to the
// slope-frame yaw (0 = facing uphill).
double HeadingFromTheta(double theta_deg) { return (theta_deg + 90.0) * kPi / 180.0; }

// The command table {-0.5, 0, 0.5}^3 without the no-op, in lexicographic order.
void FillCommandTable(SampleSet* set) {
  set->command_dim_names = {"long", "lat", "turn"};
  std::vector<Eigen::Vector3d> rows;
  const double levels[3] = {-0.5, 0.0, 0.5};
  for (double a : levels)
    for (double b : levels)
      for (double c : levels)
        if (a != 0 || b != 0 || c != 0) rows.emplace_back(a, b, c);
  set->commands.resize(static_cast<int>(rows.size()), 3);
  for (int i = 0; i < static_cast<int>(rows.size()); ++i) {
    set->commands.row(i) = rows[i].transpose();
    set->command_labels.push_back(FormatLevel(rows[i][0]) + "," + FormatLevel(rows[i][1]) + "," +
                                  FormatLevel(rows[i][2]));
  }
}

std::vector<Placement> PlanPlacements(const ProtocolOptions& options, int num_commands,
                                      std::mt19937_64& rng) {
  std::uniform_real_distribution<double> position(-1.0, 1.0);  // times the placement half-width
  std::vector<int> order(num_commands);
  std::vector<Placement> plan;
  if (options.protocol == Protocol::kPaper) {
    const int total = options.placements > 0 ? options.placements : 3 * num_commands;
    for (int i = 0; i < num_commands; ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);  // drawn without replacement
    const double thetas[3] = {0.0, 90.0, -90.0};
    for (int i = 0; i < total; ++i) {
      Placement p;
      p.command = order[(i / 3) % num_commands];
      p.heading_rad = HeadingFromTheta(thetas[i % 3]);
      p.x_unit = position(rng);
      p.y_unit = position(rng);
      plan.push_back(p);
    }
  } else if (options.protocol == Protocol::kContinuous) {
    const int total = options.placements > 0 ? options.placements : 166;
    std::uniform_real_distribution<double> heading(-kPi, kPi), level(-0.5, 0.5);
    for (int i = 0; i < total; ++i) {
      Placement p;
      p.heading_rad = heading(rng);
      p.x_unit = position(rng);
      p.y_unit = position(rng);
      for (int r = 0; r < options.executions_per_placement; ++r) {
        p.values.emplace_back(level(rng), level(rng), level(rng));
      }
      plan.push_back(p);
    }
  } else if (options.protocol == Protocol::kTrajectories) {
    const int total = options.placements > 0 ? options.placements : 100;
    std::uniform_real_distribution<double> heading(-kPi, kPi);
    std::uniform_int_distribution<int> any(0, num_commands - 1);
    for (int i = 0; i < total; ++i) {
      Placement p;
      for (int r = 0; r < options.executions_per_placement; ++r) p.sequence.push_back(any(rng));
      p.command = p.sequence[0];
      p.heading_rad = heading(rng);
      p.x_unit = position(rng);
      p.y_unit = position(rng);
      plan.push_back(p);
    }
  } else {
    const int total = options.placements > 0 ? options.placements : 166;
    std::uniform_real_distribution<double> heading(-kPi, kPi);
    for (int i = 0; i < total; ++i) {
      if (i % num_commands == 0) {  // a fresh shuffle of all commands every 26 placements
        for (int c = 0; c < num_commands; ++c) order[c] = c;
        std::shuffle(order.begin(), order.end(), rng);
      }
      Placement p;
      p.command = order[i % num_commands];
      p.heading_rad = heading(rng);
      p.x_unit = position(rng);
      p.y_unit = position(rng);
      plan.push_back(p);
    }
  }
  return plan;
}

// A tracker's error: its reading of a true pose is the position offset and the body-frame rotation
// (roll, pitch, yaw) applied to it.
struct TrackerError {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double roll_rad = 0, pitch_rad = 0, yaw_rad = 0;
  Pose Read(const Pose& truth) const {
    Pose read = truth;
    read.position_m += position_m;
    read.rotation = truth.rotation * FromRollPitchYaw(roll_rad, pitch_rad, yaw_rad);
    return read;
  }
};

TrackerError DrawTrackerError(const NoiseConfig& noise, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  TrackerError e;
  for (int k = 0; k < 3; ++k) e.position_m[k] = noise.tracker_position_sd_m * n(rng);
  e.roll_rad = noise.tracker_roll_sd_rad * n(rng);
  e.pitch_rad = noise.tracker_pitch_sd_rad * n(rng);
  e.yaw_rad = noise.tracker_yaw_sd_rad * n(rng);
  return e;
}

}  // namespace

bool TiltedBeyondThreshold(const Pose& torso_in_ground) {
  return torso_in_ground.rotation(2, 2) < std::cos(kTiltedDeg * M_PI / 180);
}

std::string ProtocolName(Protocol protocol) {
  switch (protocol) {
    case Protocol::kPaper: return "paper";
    case Protocol::kPaper830: return "paper-830";
    case Protocol::kTrajectories: return "trajectories";
    case Protocol::kContinuous: return "continuous";
  }
  return "paper";
}

Protocol ParseProtocol(const std::string& name) {
  if (name == "paper") return Protocol::kPaper;
  if (name == "paper-830") return Protocol::kPaper830;
  if (name == "trajectories") return Protocol::kTrajectories;
  if (name == "continuous") return Protocol::kContinuous;
  throw MakeInputError("", "--protocol", "expected paper, paper-830 or trajectories, got \"" + name + "\"");
}

bool ProtocolOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (executions_per_placement < 1 || executions_per_placement > 1000)
    return fail("executions_per_placement: expected 1..1000");
  if (placements < 0 || placements > 100000) return fail("placements: expected 0..100000");
  if (max_retries_per_placement < 0 || max_retries_per_placement > 100)
    return fail("max_retries_per_placement: expected 0..100");
  if (chunk_placements < 0) return fail("chunk_placements: expected >= 0");
  if (threads < 1) return fail("threads: expected >= 1");
  return true;
}

double SimSummary::SimulatedPerWallSecond() const {
  return wall_seconds > 0 ? simulated_seconds / wall_seconds : 0;
}
double SimSummary::SamplesPerWallSecond() const {
  return wall_seconds > 0 ? samples / wall_seconds : 0;
}

std::string SimSummary::BriefReport() const {
  std::ostringstream out;
  out.precision(3);
  out << samples << " samples from " << placements << " placements, " << falls << " falls ("
      << abandoned_placements << " placements abandoned); " << simulated_seconds
      << " simulated s in " << wall_seconds << " wall s, " << cpu_seconds << " CPU s (" << SimulatedPerWallSecond()
      << " sim s per wall s, " << SamplesPerWallSecond() << " samples/s)";
  return out.str();
}

namespace {

// The command (long, lat, turn) of every placement, or of every execution of a sequence.
Eigen::MatrixXd CommandsPlanned(const std::vector<Placement>& plan, const Eigen::MatrixXd& table) {
  std::vector<Eigen::Vector3d> used;
  for (const Placement& p : plan) {
    if (p.sequence.empty() && p.values.empty()) used.push_back(table.row(p.command).transpose());
    for (int id : p.sequence) used.push_back(table.row(id).transpose());
    used.insert(used.end(), p.values.begin(), p.values.end());
  }
  Eigen::MatrixXd out(static_cast<int>(used.size()), 3);
  for (int k = 0; k < out.rows(); ++k) out.row(k) = used[k].transpose();
  return out;
}

// The samples a plan recorded, in order.
struct Recorded {
  std::vector<int> command, episode, step;
  std::vector<Eigen::Matrix<double, 6, 1>> xs;
  std::vector<Eigen::VectorXd> zs;      // pitch, roll, then the sensed terrain descriptors
  std::vector<Eigen::Vector3d> values;  // the command of each sample (continuous protocol)
};

// The recorded samples into the set: x, z (continuous commands first, then pitch and roll),
// episodes, names and units.
void FillSamples(const Recorded& r, const std::vector<std::string>& sensed, SampleSet* set) {
  const int n = static_cast<int>(r.xs.size());
  set->command.resize(n);
  set->episode.resize(n);
  set->step.resize(n);
  set->x.resize(n, 6);
  const int dc = r.values.empty() ? 0 : 3;
  const int dz = 2 + static_cast<int>(sensed.size());
  set->z.resize(n, dc + dz);
  for (int i = 0; i < n; ++i) {
    set->command[i] = r.command[i];
    set->episode[i] = r.episode[i];
    set->step[i] = r.step[i];
    set->x.row(i) = r.xs[i].transpose();
    if (dc > 0) set->z.row(i).head(3) = r.values[i].transpose();
    set->z.row(i).tail(dz) = r.zs[i].transpose();
  }
  set->x_names = {"dx", "dy", "dz", "droll", "dpitch", "dyaw"};
  set->x_units = {"m", "m", "m", "rad", "rad", "rad"};
  set->z_names = {"pitch", "roll"};
  set->z_units = {"rad", "rad"};
  for (const std::string& s : sensed) {
    set->z_names.push_back(s);
    set->z_units.push_back("m");
  }
  if (dc > 0) {  // continuous commands: the first conditioning dimensions of z
    set->z_names.insert(set->z_names.begin(), {"cmd_long", "cmd_lat", "cmd_turn"});
    set->z_units.insert(set->z_units.begin(), {"command", "command", "command"});
    set->metadata["continuous_command_columns"] = "3";
  }
  set->source = "sim";
}

// The robot touched itself in some executions: say how often, where and what to do.
std::string SelfContactWarning(const SimSummary& sum, const std::string& pair, const std::string& command) {
  return "robot: its legs or body touched each other in " + std::to_string(sum.self_contact_executions) + " of " +
         std::to_string(sum.executions) + " executions (most often " + pair + ", most in command " + command +
         "); the simulation keeps those collisions as physics. If the real robot's parts cannot meet, make "
         "them collide with the ground only in the MJCF (contype/conaffinity or <contact><exclude>); if they "
         "can, shorten the gait's steps (robot.gait.stride_reach)";
}

// The torso started tilted in more than a twentieth of the executions: say how often and why it can.
std::string TiltedWarning(const SimSummary& sum, const SimConfig& config) {
  std::ostringstream w;
  w << "robot: its torso started " << sum.tilted_executions << " of " << sum.executions << " executions tilted more than "
    << kTiltedDeg << " degrees from the ground's plane, so those samples are of a robot walking tilted";
  if (!config.robot || config.robot->controller.replay()) return w.str();  // the built-in gait, or not a gait
  w << "; the gait's foot targets are fixed in the torso frame, so on uneven ground its tilt can carry over from "
       "step to step";
  if (config.robot->gait.level > 0) {
    w << " (robot.gait.level " << config.robot->gait.level << " takes back that share of it)";
  } else {
    w << ": robot.gait.level takes back a share of it at every control step (docs/simulation.md, \"Leveling\": it "
         "helps some robots and topples others; compare this count with it)";
  }
  return w.str();
}

// The sensed terrain descriptors of terrain.h at the robot's current state.
Eigen::VectorXd SensedTerrain(const Simulator& sim, const std::vector<std::string>& sensed) {
  Eigen::VectorXd v(static_cast<int>(sensed.size()));
  for (int i = 0; i < v.size(); ++i) {
    if (sensed[i] == "foot_relief") {  // the ground under each foot, as contacts report it with the feet down
      std::vector<Eigen::Vector3d> feet = sim.FootPositions();
      for (Eigen::Vector3d& f : feet) f.z() = sim.GroundHeight(f.x(), f.y());
      v[i] = FootRelief(feet);
    } else {  // height_ahead: one leg reach along the heading
      const Pose torso = sim.TorsoPose();
      Eigen::Vector2d ahead = torso.rotation.col(0).head<2>();
      ahead = ahead.norm() > 1e-9 ? ahead.normalized() : Eigen::Vector2d::UnitX();
      const Eigen::Vector2d here = torso.position_m.head<2>(), there = here + sim.leg_reach_m() * ahead;
      v[i] = sim.GroundHeight(there.x(), there.y()) - sim.GroundHeight(here.x(), here.y());
    }
  }
  return v;
}

// What one simulator recorded over a run of placements.
struct PlanRun {
  Recorded rec;
  SimSummary sum;                                    // counts only
  std::map<int, long long> self_contact_by_command;  // steps in contact per command
  std::string self_contact_pair;
  double simulated_seconds = 0;
  std::vector<std::string> robot_warnings;  // of the robot as simulated (the first run of placements only)
  double total_mass_kg = 0, leg_reach_m = 0;
};

// A stream of its own from the seed, the indices `ids` and a `tag` naming what it is for:
// seed_seq{seed low, seed high, ids..., tag}.
std::mt19937_64 SubStream(std::uint64_t seed, std::initializer_list<std::uint32_t> ids, std::uint32_t tag) {
  std::vector<std::uint32_t> words = {static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)};
  words.insert(words.end(), ids);
  words.push_back(tag);
  std::seed_seq seq(words.begin(), words.end());
  return std::mt19937_64(seq);
}

// Where an attempt at a placement draws its retry spot and sensor noise from.
struct Draws {
  std::mt19937_64& rng;
  std::normal_distribution<double>& unit;  // the IMU's (its cached second draw carries over)
};

// The sensor noise of one execution, drawn in the order the shipped sets were made in: the IMU's
// roll, then pitch, then the tracker's error at the start and at the end of the execution. The
// one place that order is written: a recording and a placement skipped (SkipPlacementDraws) both
// draw through it.
struct ExecutionNoise {
  double imu_roll_rad = 0, imu_pitch_rad = 0;
  TrackerError start, end;
};

ExecutionNoise DrawExecutionNoise(const NoiseConfig& noise, Draws draws) {
  ExecutionNoise e;
  e.imu_roll_rad = noise.imu_roll_sd_rad * draws.unit(draws.rng);
  e.imu_pitch_rad = noise.imu_pitch_sd_rad * draws.unit(draws.rng);
  e.start = DrawTrackerError(noise, draws.rng);
  e.end = DrawTrackerError(noise, draws.rng);
  return e;
}

// The stream of retry `attempt` at placement p of a recording with paired streams: from the seed,
// the placement's index and the attempt alone.
std::mt19937_64 RetryStream(std::uint64_t seed, int p, int attempt) {
  return SubStream(seed, {static_cast<std::uint32_t>(p), static_cast<std::uint32_t>(attempt)}, 0x72747279u);
}

// Advances (rng, unit) by the draws a placement of `reps` executions makes when none falls.
void SkipPlacementDraws(const NoiseConfig& noise, int reps, std::mt19937_64& rng,
                        std::normal_distribution<double>& unit) {
  for (int r = 0; r < reps; ++r) DrawExecutionNoise(noise, {rng, unit});
}

// One attempt at placement `where`: places the robot and runs its `reps` executions, their pose
// changes into px and their z into pz; false as soon as the robot falls.
bool RunAttempt(Simulator& sim, const SimConfig& config, const Placement& where, int reps,
                const Eigen::MatrixXd& commands, const std::vector<std::string>& sensed, Draws draws, PlanRun* out,
                std::vector<Eigen::Matrix<double, 6, 1>>* px, std::vector<Eigen::VectorXd>* pz) {
  SimSummary& sum = out->sum;
  const double half = sim.placement_half_width_m();
  if (sim.Place(half * where.x_unit, half * where.y_unit, where.heading_rad) != RunOutcome::kCompleted) return false;
  for (int r = 0; r < reps; ++r) {
    const int id = where.sequence.empty() ? where.command : where.sequence[r];
    const Eigen::Vector3d c = where.values.empty() ? Eigen::Vector3d(commands.row(id).transpose()) : where.values[r];
    const Eigen::Vector2d z_true = sim.TruePitchRoll();
    const Eigen::VectorXd terrain = SensedTerrain(sim, sensed);
    const ExecutionNoise noise = DrawExecutionNoise(config.noise, draws);
    Eigen::VectorXd z(2 + terrain.size());
    z[0] = z_true[0] + noise.imu_pitch_rad;
    z[1] = z_true[1] + noise.imu_roll_rad;
    z.tail(terrain.size()) = terrain;
    pz->push_back(z);
    const Pose truth = sim.TorsoPose();
    const Pose start = noise.start.Read(truth);
    if (TiltedBeyondThreshold(truth)) ++sum.tilted_executions;
    const long long touched = sim.SelfContactSteps();
    const bool fell = sim.RunCommand(c) != RunOutcome::kCompleted;
    ++sum.executions;
    if (sim.SelfContactSteps() > touched) ++sum.self_contact_executions;
    out->self_contact_by_command[id] += sim.SelfContactSteps() - touched;
    const Pose end = noise.end.Read(sim.TorsoPose());
    px->push_back(DeltaPoseBody(start, end));
    if (fell) return false;
  }
  return true;
}

// Keeps the executions of a completed attempt at placement p.
void Keep(const Placement& where, int p, const std::vector<Eigen::Matrix<double, 6, 1>>& px,
          const std::vector<Eigen::VectorXd>& pz, Recorded* rec) {
  for (size_t r = 0; r < px.size(); ++r) {
    rec->command.push_back(where.sequence.empty() ? where.command : where.sequence[r]);
    rec->episode.push_back(p);
    rec->step.push_back(static_cast<int>(r));
    rec->xs.push_back(px[r]);
    rec->zs.push_back(pz[r]);
    if (!where.values.empty()) rec->values.push_back(where.values[r]);
  }
}

// Runs placements [first, last) of `plan` on `sim`, drawing retries and sensor noise from `rng`
// (with options.paired_streams, retries from streams of their own and `rng` advanced by one
// completed placement's draws whatever happened, so that a fall does not shift later placements'
// noise: recordings of one plan at different knob values pair their noise placement by placement).
void RunPlacements(Simulator& sim, const SimConfig& config, const ProtocolOptions& options,
                   const std::vector<Placement>& plan, int first, int last, const Eigen::MatrixXd& commands,
                   std::mt19937_64& rng, const std::function<void()>& placed, PlanRun* out) {
  const int reps = options.executions_per_placement;
  const std::vector<std::string> sensed = config.terrain ? config.terrain->sensed : std::vector<std::string>();
  std::uniform_real_distribution<double> position(-1.0, 1.0);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int p = first; p < last; ++p) {
    Placement where = plan[p];
    const std::mt19937_64 rng_before = rng;
    const std::normal_distribution<double> unit_before = unit;
    bool kept = false, kept_first = false;
    for (int attempt = 0; attempt <= options.max_retries_per_placement && !kept; ++attempt) {
      const bool own = options.paired_streams && attempt > 0;
      std::mt19937_64 retry = own ? RetryStream(options.seed, p, attempt) : std::mt19937_64();
      std::normal_distribution<double> retry_unit(0.0, 1.0);
      const Draws draws{own ? retry : rng, own ? retry_unit : unit};
      if (attempt > 0) {  // re-place somewhere else on the slope, same heading and command
        where.x_unit = position(draws.rng);
        where.y_unit = position(draws.rng);
      }
      std::vector<Eigen::Matrix<double, 6, 1>> px;
      std::vector<Eigen::VectorXd> pz;
      if (!RunAttempt(sim, config, where, reps, commands, sensed, draws, out, &px, &pz)) {
        ++out->sum.falls;
        continue;
      }
      kept = true, kept_first = attempt == 0;
      Keep(where, p, px, pz, &out->rec);
    }
    if (options.paired_streams && !kept_first) {  // in step with a recording whose first attempt held
      rng = rng_before, unit = unit_before;
      SkipPlacementDraws(config.noise, reps, rng, unit);
    }
    if (!kept) ++out->sum.abandoned_placements;
    if (placed) placed();
  }
  out->simulated_seconds = sim.time_s();
  out->self_contact_pair = sim.SelfContactPair();
  if (first == 0) out->robot_warnings = sim.RobotWarnings();  // one config, one robot: once per recording
  out->total_mass_kg = sim.total_mass_kg();
  out->leg_reach_m = sim.leg_reach_m();
}

// Appends `part` (a later run of placements) to `all`.
void Append(PlanRun&& part, PlanRun* all) {
  Recorded& r = all->rec;
  Recorded& q = part.rec;
  r.command.insert(r.command.end(), q.command.begin(), q.command.end());
  r.episode.insert(r.episode.end(), q.episode.begin(), q.episode.end());
  r.step.insert(r.step.end(), q.step.begin(), q.step.end());
  r.xs.insert(r.xs.end(), q.xs.begin(), q.xs.end());
  r.zs.insert(r.zs.end(), q.zs.begin(), q.zs.end());
  r.values.insert(r.values.end(), q.values.begin(), q.values.end());
  all->sum.executions += part.sum.executions;
  all->sum.self_contact_executions += part.sum.self_contact_executions;
  all->sum.tilted_executions += part.sum.tilted_executions;
  all->sum.falls += part.sum.falls;
  all->sum.abandoned_placements += part.sum.abandoned_placements;
  for (const auto& [command, steps] : part.self_contact_by_command) all->self_contact_by_command[command] += steps;
  if (all->self_contact_pair.empty() && part.sum.self_contact_executions > 0) {
    all->self_contact_pair = part.self_contact_pair;  // the first run with contacts names the pair
  }
  all->simulated_seconds += part.simulated_seconds;
  all->robot_warnings.insert(all->robot_warnings.end(), part.robot_warnings.begin(), part.robot_warnings.end());
  all->total_mass_kg = part.total_mass_kg;
  all->leg_reach_m = part.leg_reach_m;
}

// The generator of chunk `chunk` of a chunked recording: its own stream, from the seed and the
// chunk's index alone.
std::mt19937_64 ChunkStream(std::uint64_t seed, int chunk) {
  return SubStream(seed, {static_cast<std::uint32_t>(chunk)}, 0x63686b75u);
}

// Runs the whole plan: on one simulator with the plan's generator, or (chunk_placements > 0) in
// fixed chunks, each on its own simulator and stream, on up to options.threads threads.
PlanRun RunAll(const SimConfig& config, const ProtocolOptions& options, const std::vector<Placement>& plan,
               const Eigen::MatrixXd& commands, std::mt19937_64& rng, const ProgressFn& progress,
               const ModelEdit& edit) {
  const int n = static_cast<int>(plan.size());
  std::mutex mu;
  long long done = 0;
  const std::function<void()> placed = [&] {
    if (!progress) return;
    std::lock_guard<std::mutex> lock(mu);
    progress(++done, n);
  };
  if (options.chunk_placements == 0) {
    Simulator sim(config, edit);
    PlanRun run;
    RunPlacements(sim, config, options, plan, 0, n, commands, rng, placed, &run);
    return run;
  }
  const int chunks = (n + options.chunk_placements - 1) / options.chunk_placements;
  std::vector<PlanRun> parts(chunks);
  ParallelFor(chunks, options.threads, [&](int c) {
    Simulator sim(config, edit);
    std::mt19937_64 stream = ChunkStream(options.seed, c);
    const int first = c * options.chunk_placements;
    RunPlacements(sim, config, options, plan, first, std::min(n, first + options.chunk_placements), commands,
                  stream, placed, &parts[c]);
  });
  PlanRun all;
  for (PlanRun& part : parts) Append(std::move(part), &all);
  return all;
}

// The set's samples, summary and metadata from the run.
void FinishRecording(const SimConfig& config, const ProtocolOptions& options, int placements, PlanRun&& run,
                     SimSummary* sum, SampleSet* set) {
  const std::vector<std::string> sensed = config.terrain ? config.terrain->sensed : std::vector<std::string>();
  FillSamples(run.rec, sensed, set);
  *sum = run.sum;
  sum->samples = set->size();
  sum->warnings = run.robot_warnings;
  if (sum->self_contact_executions > 0) {
    const auto worst =
        std::max_element(run.self_contact_by_command.begin(), run.self_contact_by_command.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    sum->warnings.push_back(SelfContactWarning(*sum, run.self_contact_pair, set->command_labels.at(worst->first)));
  }
  const std::string walk = WalkWarning(WalkRatios(*set, CommandedWalkOf(config, run.leg_reach_m)));
  if (!walk.empty()) sum->warnings.push_back(walk);
  if (sum->TiltedTooOften()) sum->warnings.push_back(TiltedWarning(*sum, config));
  sum->placements = placements;
  sum->simulated_seconds = run.simulated_seconds;
  auto& meta = set->metadata;
  meta["generator"] = "dgmm simulate";
  meta["protocol"] = ProtocolName(options.protocol);
  meta["seed"] = std::to_string(options.seed);
  meta["executions_per_placement"] = std::to_string(options.executions_per_placement);
  if (options.chunk_placements > 0) {
    meta["random_streams"] = "one per chunk of " + std::to_string(options.chunk_placements) + " placements";
  }
  meta["placements"] = std::to_string(sum->placements);
  meta["falls"] = std::to_string(sum->falls);
  meta["executions"] = std::to_string(sum->executions);
  meta["tilted_executions"] = std::to_string(sum->tilted_executions);
  KeepWarnings(sum->warnings, set);
  meta["abandoned_placements"] = std::to_string(sum->abandoned_placements);
  meta["simulated_seconds"] = std::to_string(sum->simulated_seconds);
  meta["robot_mass_kg"] = std::to_string(run.total_mass_kg);
  if (config.robot) meta["robot_leg_reach_m"] = std::to_string(run.leg_reach_m);
  meta["sim_config"] = SimConfigToJson(config);
  meta["x_frame"] = "torso body frame at the start of each execution (x forward, y left, z up); "
                    "angles ZYX Euler of the relative rotation";
  meta["z_frame"] = "IMU pitch/roll relative to gravity before each execution; pitch > 0 nose "
                    "down, roll > 0 left side up";
  if (!sensed.empty()) {
    meta["z_frame"] += "; foot_relief: sd of the feet's heights about their least-squares plane (m); "
                       "height_ahead: ground one leg reach ahead minus under the torso (m)";
  }
}

// Runs `plan` (placements of `options.executions_per_placement` executions each) and writes the
// set (command table already filled), its metadata and the summary.
void RunPlan(const SimConfig& config, const ProtocolOptions& options, const std::vector<Placement>& plan,
             std::mt19937_64& rng, const ProgressFn& progress, SimSummary* summary, const ModelEdit& edit,
             SampleSet* out) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  CheckRecordingsCover(config, CommandsPlanned(plan, out->commands));
  PlanRun run = RunAll(config, options, plan, out->commands, rng, progress, edit);
  SimSummary sum;
  FinishRecording(config, options, static_cast<int>(plan.size()), std::move(run), &sum, out);
  sum.cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  sum.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (summary) *summary = sum;
}

}  // namespace

SampleSet SimulateProtocol(const SimConfig& config, const ProtocolOptions& options,
                           const ProgressFn& progress, SimSummary* summary, const ModelEdit& edit) {
  std::string error;
  if (!config.IsValid(&error)) throw MakeInputError("simulation config", "", error);
  if (!options.IsValid(&error)) throw MakeInputError("protocol options", "", error);
  std::mt19937_64 rng(options.seed);
  SampleSet set;
  FillCommandTable(&set);
  const std::vector<Placement> plan = PlanPlacements(options, set.num_commands(), rng);
  if (options.protocol == Protocol::kContinuous) {  // one command: the values are in z
    set.commands = Eigen::MatrixXd::Zero(1, 3);
    set.command_labels = {"velocity"};
  }
  RunPlan(config, options, plan, rng, progress, summary, edit, &set);
  return set;
}

namespace {

// A cell's placement positions, the first draws of its seed's generator (x then y per placement).
std::vector<Eigen::Vector2d> CellPositions(int placements, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> position(-1.0, 1.0);
  std::vector<Eigen::Vector2d> out(placements);
  for (Eigen::Vector2d& p : out) {
    p.x() = position(rng);
    p.y() = position(rng);
  }
  return out;
}

}  // namespace

SampleSet SimulateCell(const SimConfig& config, const CellOptions& cell, SimSummary* summary,
                       const ModelEdit& edit) {
  std::string error;
  if (!config.IsValid(&error)) throw MakeInputError("simulation config", "", error);
  ProtocolOptions options;
  options.seed = cell.seed;
  options.executions_per_placement = cell.executions_per_placement;
  options.placements = cell.placements;
  options.max_retries_per_placement = cell.max_retries_per_placement;
  options.paired_streams = cell.paired_streams;
  if (!options.IsValid(&error) || cell.placements < 1 || !std::isfinite(cell.heading_rad)) {
    throw MakeInputError("cell options", "", error.empty() ? "placements >= 1 and a finite heading" : error);
  }
  std::mt19937_64 rng(cell.seed);
  SampleSet set;
  FillCommandTable(&set);
  int row = -1;
  for (int c = 0; c < set.num_commands(); ++c) {
    if ((set.commands.row(c).transpose() - cell.command).norm() < 1e-9) row = c;
  }
  if (row < 0) {
    // Not a protocol command: a one-row table of its own.
    set.commands = cell.command.transpose();
    set.command_labels = {"cell"};
    row = 0;
  }
  if (!cell.headings_rad.empty() && static_cast<int>(cell.headings_rad.size()) != cell.placements) {
    throw MakeInputError("cell options", "headings_rad", "expected one heading per placement");
  }
  const std::vector<Eigen::Vector2d> where = CellPositions(cell.placements, rng);
  std::vector<Placement> plan(cell.placements);
  for (int i = 0; i < cell.placements; ++i) {
    Placement& p = plan[i];
    p.command = row;
    p.heading_rad = cell.headings_rad.empty() ? cell.heading_rad : cell.headings_rad[i];
    p.x_unit = where[i].x();
    p.y_unit = where[i].y();
  }
  RunPlan(config, options, plan, rng, {}, summary, edit, &set);
  set.metadata["protocol"] = "cell";
  return set;
}

namespace {

// The heading whose settled pose at (x, y) reads closest to (pitch, roll); NaN when every heading fell.
double BestHeading(Simulator& sim, double x_m, double y_m, double pitch_rad, double roll_rad, int headings) {
  double best = NAN, best_d = INFINITY;
  for (int h = 0; h < headings; ++h) {
    const double heading = -kPi + 2 * kPi * h / headings;
    if (sim.Place(x_m, y_m, heading) != RunOutcome::kCompleted) continue;
    const Eigen::Vector2d z = sim.TruePitchRoll();
    const double d = std::hypot(z[0] - pitch_rad, z[1] - roll_rad);
    if (d < best_d) best_d = d, best = heading;
  }
  return best;
}

void CheckTerrainTarget(int headings, double pitch_rad, double roll_rad) {
  if (headings < 1 || !std::isfinite(pitch_rad) || !std::isfinite(roll_rad)) {
    throw MakeInputError("terrain", "", "headings >= 1 and a finite pitch and roll");
  }
}

}  // namespace

std::vector<double> HeadingsForTerrain(const SimConfig& config, const CellOptions& cell, double pitch_rad,
                                       double roll_rad, int headings) {
  CheckTerrainTarget(headings, pitch_rad, roll_rad);
  Simulator sim(config);
  std::mt19937_64 rng(cell.seed);
  std::vector<double> out;
  for (const Eigen::Vector2d& at : CellPositions(cell.placements, rng)) {  // those SimulateCell draws
    const double half = sim.placement_half_width_m();
    const double best = BestHeading(sim, half * at.x(), half * at.y(), pitch_rad, roll_rad, headings);
    if (!std::isfinite(best)) throw MakeInputError("terrain", "", "the robot fell at every heading at a placement");
    out.push_back(best);
  }
  return out;
}

double HeadingForTerrain(const SimConfig& config, double pitch_rad, double roll_rad, int headings,
                         const ModelEdit& edit) {
  CheckTerrainTarget(headings, pitch_rad, roll_rad);
  Simulator sim(config, edit);
  const double best = BestHeading(sim, 0.0, 0.0, pitch_rad, roll_rad, headings);
  if (!std::isfinite(best)) throw MakeInputError("terrain", "", "the robot fell at every heading");
  return best;
}

}  // namespace dgmm::sim
