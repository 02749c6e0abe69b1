#pragma once
// Internal to dgmm_sim (includes MuJoCo): can a robot's actuators carry it? At the stance, the
// weight shared by the feet on the ground (the legs times the gait's duty factor) needs joint
// torques tau = J' F at each leg (J the foot's Jacobian on the leg's joints, F the foot's share of
// the weight, upwards); a joint whose actuator's force range (times its gear) is below that cannot
// hold the robot up. Checked on the kinematics alone, before anything is simulated.
#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "sim/legged_robot.h"

namespace dgmm::sim {

// The joint that needs most of its actuator's limit.
struct StanceLoad {
  int leg = -1, joint = -1;  // the worst joint (model id) and its leg; -1: no actuator is limited
  double needed = 0;         // torque (N m) or force (N) at the joint to carry the weight
  double limit = 0;          // what its actuators can give there: force range x gear
  double feet = 0;           // feet on the ground the weight is shared by
};
StanceLoad MeasureStanceLoad(const mjModel* model, const LeggedRobot& robot);

// A warning when the worst joint needs more than its actuator's limit; empty otherwise.
std::vector<std::string> StanceLoadWarnings(const StanceLoad& load, const mjModel* model, const LeggedRobot& robot);

}  // namespace dgmm::sim
