#include "sim/pose.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace dgmm::sim {
namespace {

constexpr double kTol = 1e-9;  // pure rotations and products: round-off only

TEST(PoseTest, RollPitchYawRoundTrip) {
  std::mt19937_64 rng(0);
  std::uniform_real_distribution<double> angle(-1.4, 1.4);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d rpy(angle(rng), angle(rng), 2 * angle(rng));
    const Eigen::Vector3d back = RollPitchYaw(FromRollPitchYaw(rpy[0], rpy[1], rpy[2]));
    EXPECT_TRUE(back.isApprox(rpy, kTol)) << back.transpose() << " vs " << rpy.transpose();
  }
}

TEST(PoseTest, SignConventions) {
  // Roll > 0 lifts the left side (+y); pitch > 0 lowers the nose (+x); yaw > 0 turns left.
  EXPECT_GT((FromRollPitchYaw(0.1, 0, 0) * Eigen::Vector3d::UnitY()).z(), 0);
  EXPECT_LT((FromRollPitchYaw(0, 0.1, 0) * Eigen::Vector3d::UnitX()).z(), 0);
  EXPECT_GT((FromRollPitchYaw(0, 0, 0.1) * Eigen::Vector3d::UnitX()).y(), 0);
}

TEST(PoseTest, DeltaIsInTheStartBodyFrameAndFrameIndependent) {
  Pose start, end;
  start.position_m = {1, 2, 0};
  start.rotation = FromRollPitchYaw(0, 0, M_PI / 2);  // facing +y
  end.position_m = {1, 3, 0};                         // one metre along +y: straight ahead
  end.rotation = FromRollPitchYaw(0, 0, M_PI / 2 + 0.3);
  Eigen::Matrix<double, 6, 1> expected;
  expected << 1, 0, 0, 0, 0, 0.3;
  EXPECT_TRUE(DeltaPoseBody(start, end).isApprox(expected, kTol));
  // The same motion seen from another fixed frame gives the same delta.
  const Eigen::Matrix3d r = FromRollPitchYaw(0.2, -0.4, 1.0);
  const Eigen::Vector3d t(0.5, -3, 2);
  Pose s2{r * start.position_m + t, r * start.rotation}, e2{r * end.position_m + t, r * end.rotation};
  EXPECT_TRUE(DeltaPoseBody(s2, e2).isApprox(expected, kTol));
}

TEST(PoseTest, PitchRollFromGravityIgnoresYaw) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (double yaw : {0.0, 1.0, -2.5}) {
    const Eigen::Vector2d pr = PitchRollFromGravity(FromRollPitchYaw(0.1, -0.2, yaw), up);
    EXPECT_NEAR(pr[0], -0.2, kTol);
    EXPECT_NEAR(pr[1], 0.1, kTol);
  }
}

}  // namespace
}  // namespace dgmm::sim
