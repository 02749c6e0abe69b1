#include "sim/pose.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace dgmm::sim {

Eigen::Vector3d RollPitchYaw(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return {roll, pitch, yaw};
}

Eigen::Matrix3d FromRollPitchYaw(double roll, double pitch, double yaw) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Matrix<double, 6, 1> DeltaPoseBody(const Pose& start, const Pose& end) {
  Eigen::Matrix<double, 6, 1> x;
  x.head<3>() = start.rotation.transpose() * (end.position_m - start.position_m);
  x.tail<3>() = RollPitchYaw(start.rotation.transpose() * end.rotation);
  return x;
}

Eigen::Vector2d PitchRollFromGravity(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& up) {
  // up in the body frame = third row of R_gravity(body) = (-sin p, cos p sin r, cos p cos r).
  const Eigen::Vector3d g = rotation.transpose() * up.normalized();
  const double pitch = std::atan2(-g.x(), std::hypot(g.y(), g.z()));
  const double roll = std::atan2(g.y(), g.z());
  return {pitch, roll};
}

}  // namespace dgmm::sim
