#pragma once
// The gait controller's mathematics, free of MuJoCo: leg geometry, analytic inverse kinematics
// and the alternating-tetrapod foot trajectories driven by a command <long, lat, turn>.
#include <Eigen/Core>
#include <array>

#include "sim/sim_config.h"

namespace dgmm::sim {

// One leg in the torso frame (x forward, y left, z up) at q = 0: the hip-yaw axis is vertical
// through hip_m; the coxa reaches (coxa_out_m outward, coxa_up_m up) to the hip-pitch axis; the
// femur (femur_m) is level and the tibia (tibia_m, knee to foot centre) hangs straight down.
// Positive hip yaw turns the leg counter-clockwise; positive hip pitch and knee lift the foot.
struct LegGeometry {
  Eigen::Vector3d hip_m = Eigen::Vector3d::Zero();
  double outward_rad = 0;  // torso-frame heading of the leg at hip_yaw = 0
  double coxa_out_m = 0.05, coxa_up_m = 0;
  double femur_m = 0.12, tibia_m = 0.16;
  double foot_radius_m = 0.02;
};

// <hip_yaw, hip_pitch, knee> (rad).
using LegAngles = Eigen::Vector3d;

// Foot-centre position (torso frame) for the joint angles: forward kinematics.
Eigen::Vector3d LegForward(const LegGeometry& leg, const LegAngles& q);
// Joint angles placing the foot centre at `foot_m` (torso frame), knee above the foot-hip line;
// targets out of reach are pulled onto the reachable shell along the same direction.
LegAngles LegInverse(const LegGeometry& leg, const Eigen::Vector3d& foot_m);

// Standing foot position of a leg: femur_m beyond the hip-pitch axis, stance_height_m below the
// torso centre (foot touching the ground).
Eigen::Vector3d NominalFoot(const LegGeometry& leg, const GaitConfig& gait);

// Alternating tetrapods: legs {0, 2, 5, 7} and {1, 3, 4, 6} (0..3 left front to back, 4..7
// right). Every leg's foot moves by d_i = stride * (long, lat) + turn_rad * turn * z x p_i per
// stance (half a period), so the torso advances by d_i per half period. The pattern starts and
// ends (at whole periods) with every foot at its nominal position.
bool InTetrapodA(int leg);

// Foot target (torso frame) of leg `leg` at time t in [0, duration] of a command.
Eigen::Vector3d FootTarget(const LegGeometry& leg, int leg_index, const Eigen::Vector3d& command,
                           double t, double duration, const GaitConfig& gait);

}  // namespace dgmm::sim
