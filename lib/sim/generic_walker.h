#pragma once
// Internal to dgmm_sim: any legged robot of a RobotDescription walking on the slope with the
// generic gait (legged_robot.h). Simulator forwards to it when the config has a robot block.
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "sim/actuation_line.h"
#include "sim/legged_robot.h"
#include "sim/pose.h"
#include "sim/self_contact.h"
#include "sim/sim_config.h"
#include "sim/servo_feedforward.h"

namespace dgmm::sim {

enum class RunOutcome;  // simulator.h
class Ground;           // ground.h

// The rotation of the feet's targets (robot frame) that takes back `level` of the robot frame's
// tilt from the slope plane, its heading kept (robot.gait.level):
//   R_back = AngleAxis(-level theta, a),  (theta, a) the angle and axis of Rz(yaw)^T R;
// the identity at level 0, and at level 1 the targets lie as they would under a level torso.
Eigen::Matrix3d LevelBack(const Eigen::Matrix3d& robot_rotation, double level);

// The gait's joint targets are solved every ControlEvery physics steps, not every step: at least
// kControlsPerCycle times a gait cycle and at least every kControlPeriodS,
//   every = max(1, round(min(kControlPeriodS, period / kControlsPerCycle) / timestep)).
// The hexapod's 0.6 s cycle, on which the gait was developed, gets 60 at 100 Hz. The walk depends
// on that count, not on seconds: a copy of the hexapod a quarter of its size (a 0.3 s cycle,
// scripts/scaled_robot.py) at friction 0.57 started 8 of 390 executions reared up 48 degrees with
// 50 a cycle (and twice the original's cross-talk at 30, 100 Hz), none with 60, as the original.
inline constexpr double kControlPeriodS = 0.01;
inline constexpr double kControlsPerCycle = 60;
int ControlEvery(double period_s, double timestep_s);

class GenericWalker {
 public:
  // Binds config.robot to `model` (already compiled; the walker owns it from here) and applies
  // the experiment (slope, timestep, leg gains). Throws InputError naming the part at fault.
  // `ground` (placement and the fall test) must outlive the walker.
  GenericWalker(const SimConfig& config, MjModelPtr model, const Ground& ground, const std::string& source);

  mjModel* model() { return model_.get(); }
  // Creates the state (after any edit of the model).
  void Start();

  RunOutcome Place(double x_m, double y_m, double heading_rad);
  RunOutcome Stand(double seconds);
  // Runs the command for config.command_duration_s, calling `observe(step)` after every step.
  RunOutcome Run(const Eigen::Vector3d& command, const std::function<void(int)>& observe);

  Pose RobotPose() const;  // the robot frame (forward, left, up) in the slope frame
  std::vector<Eigen::Vector3d> FootPoints() const;  // each leg's foot, slope frame
  double time_s() const { return time_s_; }
  const mjModel* model() const { return model_.get(); }
  const mjData* data() const { return data_.get(); }
  const LeggedRobot& robot() const { return robot_; }
  const SelfContacts& self_contacts() const { return self_contacts_; }

 private:
  bool Step();
  bool Fallen() const;
  // The generic gait's joint targets at time t of a command (in u_).
  void Control(const Eigen::Vector3d& command, double t, double duration);
  // The torso's sway at the legs' cycle fractions u (robot frame): the swinging legs' targets,
  // weighted by SwingWeight.
  Eigen::Vector2d Sway(const std::vector<double>& u) const;
  void HoldStance();
  // u_ (and q_) for the standing pose, with the servo feedforward when enabled.
  void StanceTargets();
  // Each leg's share of the weight for the feedforward: its foot's contact with the ground, filtered.
  const std::vector<double>& Support();
  // Gravity's direction in the robot's heading frame (the ground's tilt at the heading).
  Eigen::Vector3d GravityAtHeading(const Eigen::Matrix3d& robot_rotation) const;
  const ReplayTrack& Recording(const Eigen::Vector3d& command) const;

  SimConfig config_;
  MjModelPtr model_;
  MjDataPtr data_, scratch_;
  LeggedRobot robot_;
  std::vector<int> sides_;          // each leg's side (+1 left, -1 right), for the gait's timing
  std::vector<Eigen::Vector2d> sway_;  // each leg's torso sway target while it swings (robot frame)
  std::vector<Eigen::VectorXd> q_;  // each leg's joint targets
  Eigen::VectorXd u_;               // the signal sent now: leg targets (gait) or every actuator's (replay)
  ActuationLine line_;
  ServoFeedforward feedforward_;   // enabled with robot.gait.servo_feedforward
  std::vector<double> support_;     // its legs' filtered contact, 0 to 1
  const Ground* ground_;
  std::string source_;
  double time_s_ = 0;
  int control_every_ = 1;
  SelfContacts self_contacts_;
};

}  // namespace dgmm::sim
