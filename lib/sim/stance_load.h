#pragma once
// Internal to dgmm_sim (includes MuJoCo): can a robot's actuators carry it? At the stance, the
// weight shared by the feet on the ground (the legs times the gait's duty factor) needs joint
// torques tau = J' F at each leg (J the foot's Jacobian on the leg's joints, F the foot's share of
// the weight, upwards); a joint whose actuator's force range (times its gear) is below that cannot
// hold the robot up. And a leg whose position servos are soft for that load gives under it: its
// foot moves by J K^-1 J' F (K the servos' stiffness, -b1 gear^2), the torso sinks at each
// touchdown and drifts (servo_feedforward.h). Checked on the kinematics alone, before anything
// is simulated.
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
  int sag_leg = -1;          // the leg whose foot gives most under its load (-1: no leg all position servos)
  double sag_m = 0;          // how far: |J K^-1 J' F|
};
StanceLoad MeasureStanceLoad(const mjModel* model, const LeggedRobot& robot);

// Whether a foot gives more than a tenth of the gait's stride under its load: enough for the drift
// to be a material share of the command (a Go1-shaped quadruped at 19% walked a quarter of its
// forward commands; our sprawled quadruped at 6% walks as commanded).
bool ServosGive(const StanceLoad& load, const LeggedRobot& robot);

// Whether a joint no servo drives lies on a leg's way from its first joint to its foot (a spring
// ankle): its give under the weight is one the gait's servo feedforward cannot take out.
bool LegsHavePassiveJoints(const mjModel* model, const LeggedRobot& robot);

// Warnings when the worst joint needs more than its actuator's limit, and when the servos give
// (ServosGive) and the gait does not carry the weight (`feedforward` false: the feedforward is
// suggested, or, with passive joints on the legs, said not to help); empty otherwise.
std::vector<std::string> StanceLoadWarnings(const StanceLoad& load, const mjModel* model, const LeggedRobot& robot,
                                            bool feedforward = false);

}  // namespace dgmm::sim
