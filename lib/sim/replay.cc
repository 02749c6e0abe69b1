#include "sim/replay.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <sstream>

#include "io/csv_reader.h"
#include "util/error.h"

namespace dgmm::sim {

ReplayTrack::ReplayTrack(std::vector<double> t, Eigen::MatrixXd values) : t_(std::move(t)), values_(std::move(values)) {}

Eigen::VectorXd ReplayTrack::At(double t_s) const {
  const double tau = std::fmod(std::max(0.0, t_s), t_.back());
  const auto hi = std::upper_bound(t_.begin(), t_.end(), tau);
  const int k = static_cast<int>(hi - t_.begin());  // t_[k - 1] <= tau < t_[k], 1 <= k < size
  const double w = (tau - t_[k - 1]) / (t_[k] - t_[k - 1]);
  return (1 - w) * values_.row(k - 1).transpose() + w * values_.row(k).transpose();
}

ReplayTrack LoadReplayTrack(const std::string& file, const std::vector<std::string>& actuators) {
  const CsvTable table = ReadCsv(file);
  const int t_col = table.Column("t");
  std::vector<int> cols;
  for (const auto& name : actuators) cols.push_back(table.Column(name));
  if (table.header.size() != actuators.size() + 1) {
    throw MakeInputError(file, "header", "expected the column t and one column per actuator of the model (" +
                                             std::to_string(actuators.size()) + "), got " +
                                             std::to_string(table.header.size()) + " columns");
  }
  if (table.records.size() < 2) throw MakeInputError(file, "", "expected at least two rows");
  std::vector<double> t;
  Eigen::MatrixXd values(static_cast<int>(table.records.size()), static_cast<int>(actuators.size()));
  for (std::size_t r = 0; r < table.records.size(); ++r) {
    const CsvRecord& record = table.records[r];
    table.CheckFieldCount(record);
    t.push_back(table.Number(record, t_col));
    const std::string line = "line " + std::to_string(record.line);
    if (r == 0 && t[0] != 0) throw MakeInputError(file, line, "column t: expected the first time to be 0");
    if (r > 0 && !(t[r] > t[r - 1])) throw MakeInputError(file, line, "column t: expected increasing times");
    for (std::size_t a = 0; a < cols.size(); ++a) values(static_cast<int>(r), static_cast<int>(a)) = table.Number(record, cols[a]);
  }
  return ReplayTrack(std::move(t), std::move(values));
}

int FindRecording(const ControllerDescription& controller, const Eigen::Vector3d& command) {
  for (std::size_t i = 0; i < controller.recordings.size(); ++i) {
    if ((controller.recordings[i].command - command).norm() < 1e-9) return static_cast<int>(i);
  }
  return -1;
}

void CheckRecordingsCover(const SimConfig& config, const Eigen::MatrixXd& commands) {
  if (!config.robot || !config.robot->controller.replay()) return;
  int missing = 0, first = -1;
  for (int i = 0; i < commands.rows(); ++i) {
    if (FindRecording(config.robot->controller, commands.row(i).transpose()) >= 0) continue;
    if (missing++ == 0) first = i;
  }
  if (missing == 0) return;
  char what[200];
  std::snprintf(what, sizeof what, "no recording of command [%g, %g, %g] (%d of the %d planned commands have none)",
                commands(first, 0), commands(first, 1), commands(first, 2), missing, static_cast<int>(commands.rows()));
  throw MakeInputError(config.mjcf_path, "robot.controller.recordings", what);
}

std::string ReplayBytes(const SimConfig& config) {
  std::string bytes;
  if (!config.robot || !config.robot->controller.replay()) return bytes;
  for (const auto& rec : config.robot->controller.recordings) {
    std::ifstream in(rec.file, std::ios::binary);
    if (!in) throw MakeInputError(rec.file, "", "cannot open the replay recording");
    std::stringstream text;
    text << in.rdbuf();
    bytes += text.str() + "\n";
  }
  return bytes;
}

}  // namespace dgmm::sim
