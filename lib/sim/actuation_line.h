#pragma once
// Internal to dgmm_sim (includes MuJoCo): actuator signals on their way to the actuators. A value
// sent now reaches them latency_steps physics steps later; position targets of joint servos are
// joint values (rad or m) that pass the backlash dead band q' = q + sign(e) max(0, |e| - b/2),
// e = target - q, and reach the servo as the ctrl at which it holds the joint at q': for MuJoCo's
// position actuator ctrl = gear q' (it applies kp (ctrl - gear q)), for any affine servo
// ctrl = -(b0 + b1 gear q') / gain. Used by the generic gait and the replay controller.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace dgmm::sim {

// A servo's ctrl for joint value q: ctrl = offset + scale q, where gain ctrl + b0 + b1 gear q = 0.
struct ServoMap {
  double scale = 1, offset = 0;
};
// For actuator a when it is a fixed-gain, affine-bias servo (b1 < 0, gain != 0) on a joint.
std::optional<ServoMap> JointServoMap(const mjModel* model, int a);

class ActuationLine {
 public:
  ActuationLine() = default;
  // `actuators`: the ids the signal vector addresses, in order. backlash_rad applies to those
  // that are position servos on a joint (others pass unchanged).
  ActuationLine(const mjModel* model, std::vector<int> actuators, int latency_steps, double backlash_rad);

  // Nothing in flight: the actuators see `u` from now on.
  void Reset(const Eigen::VectorXd& u);
  // Sends `u`; call once per physics step (the line advances one step per call).
  void Send(const Eigen::VectorXd& u);
  // Writes what the actuators see into data->ctrl (with the dead band); call before each step.
  void Write(mjData* data) const;

 private:
  std::vector<int> actuators_;
  std::vector<int> backlash_qpos_;  // per signal: the joint's qpos address, or -1 (no dead band)
  std::vector<double> ctrl_scale_, ctrl_offset_;  // per signal: ctrl = offset + scale x target
  std::vector<Eigen::VectorXd> pending_;  // ring; pending_[head_] is the oldest
  int head_ = 0;
  Eigen::VectorXd seen_;
  double half_backlash_ = 0;
};

}  // namespace dgmm::sim
