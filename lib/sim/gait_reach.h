#pragma once
// Internal to dgmm_sim (includes MuJoCo): can a robot's legs make the steps the generic gait asks
// for? A leg whose joints move its foot in one plane only (hip pitch and knee, no sideways joint)
// cannot step sideways or turn, and the gait's inverse kinematics then quietly leaves the foot
// short of its target. Checked on the kinematics alone, before anything is simulated.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/legged_robot.h"

namespace dgmm::sim {

// A foot's travel relative to the torso per stance for command c (long, lat, turn in [-1, 1]):
//   d = duty (stride (long, lat) + turn_rad turn (-p_y, p_x)),  p the foot's stance point.
Eigen::Vector2d FootTravel(const LeggedRobot& robot, const LegChain& leg, const Eigen::Vector3d& c, double turn_rad);

// The worst miss of one leg over one cycle of one command.
struct GaitMiss {
  Eigen::Vector3d command = Eigen::Vector3d::Zero();
  int leg = -1;
  double residual_m = 0;  // largest distance between a foot target and where the joints put the foot
  double travel_m = 0;    // |d| of that leg in that command
};

// For each pure command at full scale (forward, lateral, turn, both signs) and each leg, the foot's
// targets at `phases` points of a cycle (stance point plus FootOffset; no lean or sway) solved by
// inverse kinematics from the stance, each phase starting from the last one's joints.
std::vector<GaitMiss> MeasureGaitMisses(const mjModel* model, const LeggedRobot& robot, double turn_rad,
                                        int phases = 16);

// Warnings for commands whose feet miss their targets by more than `share` of their travel (the
// commands named, the legs, the worst miss); empty when every foot follows.
std::vector<std::string> GaitReachWarnings(const std::vector<GaitMiss>& misses, const LeggedRobot& robot,
                                           double share = 0.25);

}  // namespace dgmm::sim
