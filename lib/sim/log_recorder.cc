#include "sim/log_recorder.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>

#include "sim/simulator.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

struct Mode {
  const char* name;
  double long_, lat, turn;
};
constexpr Mode kModes[] = {{"forward", 0.5, 0, 0},  {"back", -0.5, 0, 0},
                           {"left", 0, 0.5, 0},     {"right", 0, -0.5, 0},
                           {"turn_left", 0, 0, 0.5}, {"turn_right", 0, 0, -0.5}};
constexpr Mode kStop = {"stop", 0, 0, 0};

// An open CSV file written through a temporary (std::FILE owned here).
class CsvOut {
 public:
  CsvOut(const std::filesystem::path& path, const char* header) : file_(path) {
    f_ = std::fopen(file_.temp_path().c_str(), "w");
    if (!f_) throw MakeInputError(path.string(), "", "cannot open for writing");
    std::fprintf(f_, "%s\n", header);
  }
  ~CsvOut() {
    if (f_) std::fclose(f_);
  }
  std::FILE* get() { return f_; }
  void Commit() {
    const bool ok = std::fclose(f_) == 0;
    f_ = nullptr;
    if (!ok) throw MakeInputError(file_.target().string(), "", "write failed");
    file_.Commit();
  }

 private:
  AtomicFile file_;
  std::FILE* f_ = nullptr;
};

}  // namespace

bool LogRecordOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) { *error = m; return false; };
  if (sessions < 1) return fail("sessions: expected >= 1");
  if (commands_per_session < 1) return fail("commands per session: expected >= 1");
  if (!(command_hz > 0 && pose_hz > 0 && imu_hz > 0)) return fail("rates: expected > 0 Hz");
  if (!(gap_min_s > 0 && gap_max_s >= gap_min_s)) return fail("gaps: expected 0 < min <= max");
  if (!(command_jitter >= 0) || !(dropout_probability >= 0 && dropout_probability < 1)) {
    return fail("noise: expected jitter >= 0 and dropout probability in [0, 1)");
  }
  return true;
}

namespace {

// The pose and IMU streams of one session: each at its own rate and phase, stamped in log time
// (sim time + clock offset), with the config's sensor noise, stamp jitter and pose dropouts.
// `unit` is the recording's one normal distribution (it keeps a spare draw between calls).
class SensorStreams {
 public:
  SensorStreams(CsvOut& pose, CsvOut& imu, const NoiseConfig& noise, const LogRecordOptions& options,
                std::mt19937_64& rng, std::normal_distribution<double>& unit, double start_s, double clock_offset,
                LogRecordSummary* summary)
      : pose_(pose), imu_(imu), noise_(noise), options_(options), rng_(rng), unit_(unit), offset_(clock_offset),
        summary_(summary) {
    next_pose_ = start_s + uniform_(rng_) / options.pose_hz;
    next_imu_ = start_s + uniform_(rng_) / options.imu_hz;
  }
  // Writes every row due by the simulator's time.
  void Log(const Simulator& s) {
    const double t = s.time_s();
    while (t >= next_imu_) {
      WriteImu(t, s.TruePitchRoll());
      next_imu_ += 1.0 / options_.imu_hz;
    }
    while (t >= next_pose_) {
      WritePose(t, s.TorsoPose());
      next_pose_ += 1.0 / options_.pose_hz;
    }
  }

 private:
  void WriteImu(double t, const Eigen::Vector2d& pr) {
    std::fprintf(imu_.get(), "%.0f,%.3f,%.3f\n", (t + offset_) * 1000.0,
                 (pr[1] + noise_.imu_roll_sd_rad * unit_(rng_)) * kRadToDeg,
                 (pr[0] + noise_.imu_pitch_sd_rad * unit_(rng_)) * kRadToDeg);
    ++summary_->imu_rows;
  }
  void WritePose(double t, const Pose& p) {
    const Eigen::Vector3d rpy = RollPitchYaw(p.rotation);
    const double stamp = t + offset_ + 0.002 * (uniform_(rng_) - 0.5);  // stamp jitter
    if (uniform_(rng_) < options_.dropout_probability) {
      std::fprintf(pose_.get(), "%.4f,nan,nan,nan,nan,nan,nan\n", stamp);
      ++summary_->dropouts;
    } else {
      double yaw = rpy[2] + noise_.tracker_yaw_sd_rad * unit_(rng_);
      yaw = std::remainder(yaw, 2 * std::numbers::pi);
      std::fprintf(pose_.get(), "%.4f,%.1f,%.1f,%.1f,%.3f,%.3f,%.3f\n", stamp,
                   (p.position_m[0] + noise_.tracker_position_sd_m * unit_(rng_)) * 1000,
                   (p.position_m[1] + noise_.tracker_position_sd_m * unit_(rng_)) * 1000,
                   (p.position_m[2] + noise_.tracker_position_sd_m * unit_(rng_)) * 1000,
                   (rpy[0] + noise_.tracker_roll_sd_rad * unit_(rng_)) * kRadToDeg,
                   (rpy[1] + noise_.tracker_pitch_sd_rad * unit_(rng_)) * kRadToDeg, yaw * kRadToDeg);
    }
    ++summary_->pose_rows;
  }

  CsvOut& pose_;
  CsvOut& imu_;
  const NoiseConfig& noise_;
  const LogRecordOptions& options_;
  std::mt19937_64& rng_;
  std::normal_distribution<double>& unit_;
  double offset_;
  LogRecordSummary* summary_;
  double next_pose_ = 0, next_imu_ = 0;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
};

// Runs one mode for command_duration_s while the controller publishes it (when issued, then at
// command_hz, with jitter) and the sensors log; false when the robot fell.
bool RunMode(Simulator& sim, const Mode& mode, const LogRecordOptions& options, double duration_s,
             double clock_offset, std::mt19937_64& rng, std::normal_distribution<double>& unit, CsvOut& commands,
             SensorStreams& sensors, LogRecordSummary* summary) {
  const Eigen::Vector3d command(mode.long_, mode.lat, mode.turn);
  double next_command = sim.time_s();
  const double command_end = next_command + duration_s;
  auto log_command = [&](const Simulator& s) {
    while (s.time_s() + 1e-9 >= next_command && next_command < command_end - 1e-6) {
      std::fprintf(commands.get(), "%.4f,%s,%.3f,%.3f,%.3f\n", next_command + clock_offset, mode.name,
                   mode.long_ + options.command_jitter * unit(rng), mode.lat + options.command_jitter * unit(rng),
                   mode.turn + options.command_jitter * unit(rng));
      ++summary->command_rows;
      next_command += 1.0 / options.command_hz;
    }
  };
  log_command(sim);
  const RunOutcome outcome = sim.RunCommand(
      command, [&](const Simulator& s) { log_command(s); sensors.Log(s); }, 1);
  return outcome == RunOutcome::kCompleted;
}

}  // namespace

// Per session: a gap on the log clock, a random placement, one idle cycle of sensors before the
// first command, random modes, then "stop" published for two cycles.
LogRecordSummary RecordLog(const SimConfig& config, const LogRecordOptions& options,
                           const std::string& folder,
                           const std::function<void(long long, long long)>& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "log options", error);
  const std::filesystem::path dir(folder);
  CsvOut commands(dir / "commands.csv", "t,mode,v_long,v_lat,v_turn");
  CsvOut pose(dir / "pose.csv", "t,x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg");
  CsvOut imu(dir / "imu.csv", "t_ms,roll_deg,pitch_deg");

  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Simulator sim(config);
  LogRecordSummary summary;
  double clock_offset = options.start_time_s;  // log time = sim time + offset
  for (int session = 0; session < options.sessions; ++session) {
    if (session > 0) {
      clock_offset += options.gap_min_s + (options.gap_max_s - options.gap_min_s) * uniform(rng);
    }
    const double half = sim.placement_half_width_m();
    const double x = half * (2 * uniform(rng) - 1), y = half * (2 * uniform(rng) - 1);
    const double heading = std::numbers::pi * (2 * uniform(rng) - 1);
    if (sim.Place(x, y, heading) != RunOutcome::kCompleted) {
      ++summary.falls;
      continue;
    }
    const double session_start = sim.time_s();
    SensorStreams sensors(pose, imu, config.noise, options, rng, unit, session_start, clock_offset, &summary);
    sensors.Log(sim);
    auto log = [&](const Simulator& s) { sensors.Log(s); };
    bool ok = sim.RunCommand(Eigen::Vector3d::Zero(), log, 1) == RunOutcome::kCompleted;
    const double duration = config.command_duration_s;
    for (int c = 0; c < options.commands_per_session && ok; ++c) {
      const Mode& mode = kModes[static_cast<int>(uniform(rng) * std::size(kModes)) % std::size(kModes)];
      ok = RunMode(sim, mode, options, duration, clock_offset, rng, unit, commands, sensors, &summary);
    }
    for (int k = 0; k < 2 && ok; ++k) {
      ok = RunMode(sim, kStop, options, duration, clock_offset, rng, unit, commands, sensors, &summary);
    }
    if (!ok) ++summary.falls;
    summary.simulated_seconds += sim.time_s() - session_start;
    ++summary.sessions;
    if (progress) progress(session + 1, options.sessions);
  }
  commands.Commit();
  pose.Commit();
  imu.Commit();
  return summary;
}

}  // namespace dgmm::sim
