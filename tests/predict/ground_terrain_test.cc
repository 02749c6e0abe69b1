// lib/predict/ground_terrain.h: the terrain read off a plane and off a height field, against
// closed forms.
#include "predict/ground_terrain.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"

namespace dgmm::predict {
namespace {

MotionModel WithTerrain(std::vector<std::string> names) {
  MotionModel m;
  m.pose_dim = 3;
  m.pose_names = {"dx", "dy", "dyaw"};
  m.terrain_dim = static_cast<int>(names.size());
  m.terrain_names = std::move(names);
  return m;
}

// Six feet of a hexapod-like footprint (m, robot frame).
std::vector<Eigen::Vector2d> Footprint() {
  return {{0.2, 0.15}, {0, 0.2}, {-0.2, 0.15}, {0.2, -0.15}, {0, -0.2}, {-0.2, -0.15}};
}

TEST(GroundTerrainTest, APlaneGivesTheClosedFormPitchAndRoll) {
  const auto z = GroundTerrain(WithTerrain({"pitch", "roll"}), {0.2});
  for (double yaw : {0.0, 0.7, M_PI / 2, 2.5, -1.2}) {
    const Eigen::VectorXd v = z(Eigen::Vector4d(1, -2, 0, yaw));
    const double pitch = std::asin(-std::sin(0.2) * std::cos(yaw));
    EXPECT_NEAR(v[0], pitch, 1e-12) << yaw;
    EXPECT_NEAR(v[1], std::asin(-std::sin(0.2) * std::sin(yaw) / std::cos(pitch)), 1e-12) << yaw;
  }
}

TEST(GroundTerrainTest, ARampInTheHeightFieldAddsToTheSlope) {
  // A height field rising at angle b along x on a plane tilted by a is a plane tilted by a + b
  // (headings along and across the slope: elsewhere the two planes measure yaw differently).
  const double a = 0.1, b = 0.15;
  GroundSurface ramp{a, [b](double x, double) { return std::tan(b) * x; }, Footprint(), 0.3};
  const MotionModel m = WithTerrain({"roll", "pitch", "foot_relief"});
  const auto on_ramp = GroundTerrain(m, ramp);
  const auto steeper = GroundTerrain(m, {a + b});
  for (double yaw : {0.0, M_PI / 2, M_PI, -M_PI / 2}) {
    const Eigen::Vector4d pose(0.3, 0.2, 0, yaw);
    EXPECT_NEAR((on_ramp(pose) - steeper(pose)).norm(), 0, 1e-9) << yaw;
  }
  EXPECT_NEAR(on_ramp(Eigen::Vector4d(0, 0, 0, 0))[2], 0, 1e-12);  // the feet lie on a plane
}

TEST(GroundTerrainTest, AStoneUnderTheFrontFeetLiftsTheNoseAndShowsInTheRelief) {
  // Flat level ground with a 5 cm block under x > 0.1: the front feet stand on it.
  GroundSurface stone{0, [](double x, double) { return x > 0.1 ? 0.05 : 0.0; }, Footprint(), 0.3};
  const auto z = GroundTerrain(WithTerrain({"pitch", "roll", "foot_relief", "height_ahead"}), stone);
  const Eigen::VectorXd facing = z(Eigen::Vector4d(0, 0, 0, 0));
  EXPECT_LT(facing[0], -0.05);  // nose up (pitch > 0 is nose down)
  EXPECT_NEAR(facing[1], 0, 1e-12);
  EXPECT_GT(facing[2], 0.005);              // three heights off the feet's plane
  EXPECT_NEAR(facing[3], 0.05, 1e-12);      // the block one reach ahead
  const Eigen::VectorXd away = z(Eigen::Vector4d(0, 0, 0, M_PI));  // the block behind
  EXPECT_GT(away[0], 0.05);
  EXPECT_NEAR(away[3], 0, 1e-12);
  const Eigen::VectorXd across = z(Eigen::Vector4d(0, 0, 0, M_PI / 2));  // the block on the right
  EXPECT_LT(across[1], -0.05);  // right side up: roll < 0
}

TEST(GroundTerrainTest, WhatAGroundCannotGiveIsRefused) {
  EXPECT_THROW(GroundTerrain(WithTerrain({"pitch", "speed"}), {0.1}), InputError);
  EXPECT_THROW(GroundTerrain(WithTerrain({}), {0.1}), InputError);
  GroundSurface two_feet{0, [](double, double) { return 0.0; }, {{0.1, 0}, {-0.1, 0}}, 0.2};
  EXPECT_THROW(GroundTerrain(WithTerrain({"pitch"}), two_feet), InputError);
  GroundSurface in_a_line{0, [](double, double) { return 0.0; }, {{0.1, 0}, {0, 0}, {-0.1, 0}}, 0.2};
  EXPECT_THROW(GroundTerrain(WithTerrain({"pitch"}), in_a_line), InputError);
}

}  // namespace
}  // namespace dgmm::predict
