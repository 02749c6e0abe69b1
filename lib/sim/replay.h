#pragma once
// Recorded actuator signals replayed as a robot's controller (robot.controller type replay,
// robot_description.h): one CSV per command, a column `t` and one per actuator, MuJoCo-free.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/robot_description.h"
#include "sim/sim_config.h"

namespace dgmm::sim {

// u(t) = the rows linearly interpolated at t mod period, period = the last row's t.
class ReplayTrack {
 public:
  // `values` has one row per time in `t` (t[0] = 0, strictly increasing, at least two rows).
  ReplayTrack(std::vector<double> t, Eigen::MatrixXd values);
  Eigen::VectorXd At(double t_s) const;
  double period_s() const { return t_.back(); }
  int signals() const { return static_cast<int>(values_.cols()); }

 private:
  std::vector<double> t_;
  Eigen::MatrixXd values_;
};

// Reads `file` (InputError "<file>: line L: ..." or "<file>: column ...: ..."): column t and
// exactly the columns `actuators` (any order), returned in the order of `actuators`.
ReplayTrack LoadReplayTrack(const std::string& file, const std::vector<std::string>& actuators);

// The recording of `command` in `controller`, or -1.
int FindRecording(const ControllerDescription& controller, const Eigen::Vector3d& command);

// InputError "<config.mjcf_path>: robot.controller.recordings: ..." naming the first of the
// commands (rows of `commands`: long, lat, turn) that a replay has no recording of.
void CheckRecordingsCover(const SimConfig& config, const Eigen::MatrixXd& commands);

// The recordings' bytes, in order (part of a simulation's cache key); "" without a replay.
std::string ReplayBytes(const SimConfig& config);

}  // namespace dgmm::sim
