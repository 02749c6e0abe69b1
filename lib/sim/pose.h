#pragma once
// Rigid poses of the torso and the quantities the protocol records from them. Angles are ZYX
// (yaw-pitch-roll) Euler angles, R = Rz(yaw) Ry(pitch) Rx(roll), in a z-up frame: roll > 0 lifts
// the left side, pitch > 0 lowers the nose, yaw > 0 turns left.
#include <Eigen/Core>

namespace dgmm::sim {

// Torso pose in a fixed frame: position (m) and rotation body -> frame.
struct Pose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

// <roll, pitch, yaw> (rad) with R = Rz(yaw) Ry(pitch) Rx(roll); pitch in [-pi/2, pi/2].
Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& rotation);
// Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d FromRollPitchYaw(double roll, double pitch, double yaw);

// x = <dx, dy, dz, droll, dpitch, dyaw>: the pose `end` seen from the body frame of `start`,
// i.e. R_s^T (p_e - p_s) and the ZYX angles of R_s^T R_e. Independent of the fixed frame.
Eigen::Matrix<double, 6, 1> DeltaPoseBody(const Pose& start, const Pose& end);

// z = <pitch, roll> (rad) of the torso relative to gravity: `up` is the unit vector against
// gravity in the same frame as `rotation` (body -> frame). Yaw plays no part.
Eigen::Vector2d PitchRollFromGravity(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& up);

}  // namespace dgmm::sim
