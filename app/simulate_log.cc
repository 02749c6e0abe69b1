// `dgmm simulate-log`: a time-stamped multi-rate CSV log (commands, pose, IMU) recorded with the
// simulated robot (sim/log_recorder.h): realistic input for `dgmm import-log`.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "app/command.h"
#include "sim/log_recorder.h"
#include "sim/sim_config.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct SimulateLogArgs {
  std::string config_path, folder;
  sim::LogRecordOptions log;
  bool quiet = false;
};

void Run(const SimulateLogArgs& args) {
  const sim::SimConfig config =
      args.config_path.empty() ? sim::SimConfig{} : sim::LoadSimConfig(args.config_path);
  if (!std::filesystem::is_directory(args.folder)) {
    throw MakeInputError(args.folder, "", "folder does not exist");
  }
  const sim::LogRecordSummary s = sim::RecordLog(
      config, args.log, args.folder, [&](long long done, long long total) {
        ReportProgress("simulate-log: session", done, total);
      });
  std::printf(
      "wrote %s/{commands,pose,imu}.csv: %d sessions (%d falls), %.1f s simulated; rows: %lld "
      "commands, %lld pose (%lld dropouts), %lld imu\n",
      args.folder.c_str(), s.sessions, s.falls, s.simulated_seconds, s.command_rows, s.pose_rows,
      s.dropouts, s.imu_rows);
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<SimulateLogArgs>();
  CLI::App* cmd = root.add_subcommand(
      "simulate-log",
      "Record a time-stamped log with the simulated robot: commands.csv (10 Hz, text modes and "
      "noisy joystick values), pose.csv (30 Hz, mm and degrees, dropouts) and imu.csv (50 Hz, "
      "ms and degrees), sessions separated by logging gaps (input for import-log)");
  cmd->add_option("-o,--output-dir", args->folder, "folder to write the three CSV files into")
      ->required();
  cmd->add_option("--config", args->config_path, "simulation config (JSON, docs/simulation.md)");
  cmd->add_option("--seed", args->log.seed, "random seed: same seed, same files")
      ->capture_default_str();
  cmd->add_option("--sessions", args->log.sessions, "sessions (placements)")->capture_default_str();
  cmd->add_option("--commands-per-session", args->log.commands_per_session,
                  "commands run back to back in each session")
      ->capture_default_str();
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("simulate-log", Setup);
}  // namespace dgmm::app
