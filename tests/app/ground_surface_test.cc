// The ground of a simulation config as prediction reads it (app/wiring/ground_surface.h), against
// what the simulated robot's IMU reads standing on that ground.
#include "app/wiring/ground_surface.h"

#include <gtest/gtest.h>

#include <random>

#include "sim/simulator.h"

namespace dgmm::app {
namespace {

MotionModel PitchRollModel() {
  MotionModel m;
  m.pose_dim = 3;
  m.pose_names = {"dx", "dy", "dyaw"};
  m.terrain_dim = 2;
  m.terrain_names = {"pitch", "roll"};
  return m;
}

// The built-in octopod on a 10 degree slope strewn with stones 6 cm tall (about half its stance
// height), in a small field.
sim::SimConfig StonyGround() {
  sim::SimConfig c;
  c.slope_deg = 10;
  sim::TerrainDescription t;
  t.seed = 5;
  t.half_size_m = 1.5;
  t.stones = {0.06, 0.12, 3.0};
  c.terrain = t;
  return c;
}

TEST(GroundSurfaceTest, TheFootprintIsTheRobotsStance) {
  const predict::GroundSurface g = GroundSurfaceOf(StonyGround());
  ASSERT_EQ(g.footprint_m.size(), 8u);
  int left = 0;
  for (const Eigen::Vector2d& f : g.footprint_m) left += f.y() > 0;
  EXPECT_EQ(left, 4);
  EXPECT_GT(g.reach_m, 0.1);
  EXPECT_NEAR(g.slope_rad, 10 * M_PI / 180, 1e-12);
  EXPECT_FALSE(GroundSurfaceOf(sim::SimConfig()).height);  // a plane needs no footprint
}

TEST(GroundSurfaceTest, TheHeightFieldPredictsThePitchAndRollTheRobotStandsAt) {
  const sim::SimConfig config = StonyGround();
  const MotionModel m = PitchRollModel();
  const auto rough = predict::GroundTerrain(m, GroundSurfaceOf(config));
  const auto plane = predict::GroundTerrain(m, {config.slope_deg * M_PI / 180});
  sim::Simulator sim(config);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> position(-1.0, 1.0), heading(-M_PI, M_PI);
  double rough_error = 0, plane_error = 0;
  int placed = 0;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector4d pose(position(rng), position(rng), 0, heading(rng));
    if (sim.Place(pose[0], pose[1], pose[3]) != sim::RunOutcome::kCompleted) continue;
    const sim::Pose torso = sim.TorsoPose();
    const Eigen::Vector4d at(torso.position_m.x(), torso.position_m.y(), 0,
                             std::atan2(torso.rotation(1, 0), torso.rotation(0, 0)));
    const Eigen::Vector2d imu = sim.TruePitchRoll();
    rough_error += (rough(at) - imu).squaredNorm();
    plane_error += (plane(at) - imu).squaredNorm();
    ++placed;
  }
  ASSERT_GE(placed, 30);
  std::printf("rms pitch/roll error over %d placements: height field %.4f rad, plane alone %.4f rad\n", placed,
              std::sqrt(rough_error / placed), std::sqrt(plane_error / placed));
  EXPECT_LT(rough_error, 0.75 * plane_error);  // the stones are read, not ignored (measured: 0.52)
}

}  // namespace
}  // namespace dgmm::app
