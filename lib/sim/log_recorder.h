#pragma once
// A time-stamped robot log recorded in simulation, written as three CSV streams at different
// rates and in the units robots often log in: the input for `dgmm import-log` examples and tests
// (docs/log-import.md). Sessions are separated by logging gaps (the robot is re-placed).
//   commands.csv  t [s], mode (text label), v_long, v_lat, v_turn (joystick values with jitter)
//   pose.csv      t [s], x_mm, y_mm, z_mm, roll_deg, pitch_deg, yaw_deg (yaw wrapped to +-180)
//   imu.csv       t_ms [ms], roll_deg, pitch_deg (attitude relative to gravity)
#include <cstdint>
#include <functional>
#include <string>

#include "sim/sim_config.h"

namespace dgmm::sim {

struct LogRecordOptions {
  std::uint64_t seed = 0;
  int sessions = 5;
  int commands_per_session = 30;
  double command_hz = 10, pose_hz = 30, imu_hz = 50;
  double gap_min_s = 20, gap_max_s = 60;   // pause in logging between sessions
  double start_time_s = 1700000000.0;      // first session's clock (Unix time)
  double command_jitter = 0.03;            // sd of the noise on the logged joystick values
  double dropout_probability = 0.003;      // pose rows logged as "nan" (tracker lost)

  bool IsValid(std::string* error) const;
};

struct LogRecordSummary {
  long long command_rows = 0, pose_rows = 0, imu_rows = 0, dropouts = 0;
  int sessions = 0, falls = 0;
  double simulated_seconds = 0;
};

// Runs the sessions (each: a random placement on the slope, one idle gait cycle with the sensors
// logging, commands drawn at random from forward, back, left, right, turn_left, turn_right at
// |0.5|, then "stop" (stepping in place) for two cycles) and writes the three files into
// `folder` (atomically). Same config, options and seed: the same files.
LogRecordSummary RecordLog(const SimConfig& config, const LogRecordOptions& options,
                           const std::string& folder,
                           const std::function<void(long long, long long)>& progress = {});

}  // namespace dgmm::sim
