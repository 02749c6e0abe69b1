// The height field ground in MuJoCo (lib/sim/ground.h) and the simulator on it.
#include "sim/ground.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "mujoco_fixture.h"
#include "sim/mujoco_model.h"
#include "sim/simulator.h"

namespace dgmm::sim {
namespace {

using GroundTest = test::MujocoTest;
namespace fs = std::filesystem;

TerrainDescription Stony(std::uint64_t seed = 5) {
  TerrainDescription t;
  t.seed = seed;
  t.half_size_m = 2.0;
  t.resolution_m = 0.04;
  t.rough = {0.01, 0.16};
  t.stones = {0.04, 0.08, 3};
  return t;
}

SimConfig OnGround(const TerrainDescription& t, double slope_deg = 0) {
  SimConfig c;
  c.slope_deg = slope_deg;
  c.terrain = t;
  return c;
}

// Height of the first geom hit by a ray straight down from 1 m above (x, y), static geoms only.
double RayHeight(const mjModel* m, const mjData* d, double x, double y) {
  const mjtNum from[3] = {x, y, 1.0}, down[3] = {0, 0, -1};
  int geom = -1;
  const mjtNum dist = mj_ray(m, d, from, down, nullptr, 1, -1, &geom);
  return dist < 0 ? -1e9 : 1.0 - dist;
}

TEST_F(GroundTest, MujocoSeesTheGeneratedHeights) {
  const SimConfig c = OnGround(Stony());
  const Ground ground(c);
  MjModelPtr m = ground.Load(c);
  const int floor = mj_name2id(m.get(), mjOBJ_GEOM, "floor");
  ground.Install(m.get(), floor, "test");
  MjDataPtr d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());
  const HeightField& f = *ground.field();
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> cell(1, f.size() - 2);
  for (int i = 0; i < 50;) {  // at grid points away from the robot: the same numbers (floats in MuJoCo)
    const int r = cell(rng), col = cell(rng);
    const double x = -f.half_size_m() + col * f.resolution_m(), y = -f.half_size_m() + r * f.resolution_m();
    if (std::max(std::abs(x), std::abs(y)) < 0.8) continue;  // the robot stands at the origin
    ++i;
    EXPECT_NEAR(RayHeight(m.get(), d.get(), x, y), f.heights()[r * f.size() + col], 1e-5) << x << " " << y;
  }
  EXPECT_EQ(m->geom_contype[floor], 0);  // the plane is retired
  const int g = mj_name2id(m.get(), mjOBJ_GEOM, "dgmm_ground");
  EXPECT_EQ(m->geom_friction[3 * g], m->geom_friction[3 * floor]);
  EXPECT_EQ(m->geom_conaffinity[g], 1);
}

TEST_F(GroundTest, PlacementPutsEveryFootOnTheGroundNotInIt) {
  TerrainDescription t;
  t.half_size_m = 2.0;
  t.resolution_m = 0.02;
  t.steps = {0.06, 0.3};  // terraces higher than the feet: a robot placed on the plane would sink in
  SimConfig c = OnGround(t);
  c.settle_duration_s = 0;  // look at the moment of release
  Simulator sim(c);
  const HeightField f = HeightField::Generate(t);
  for (const double x : {0.05, 0.35, -0.25}) {
    ASSERT_EQ(sim.Place(x, 0.1, 0.3), RunOutcome::kCompleted);
    int feet = 0;
    for (const GeomSnapshot& g : sim.Geometry()) {
      if (g.type != GeomSnapshot::Type::kSphere) continue;
      ++feet;
      const Eigen::Vector3d p = g.position_m;
      EXPECT_GE(p.z() - g.size[0], f.At(p.x(), p.y()) - 1e-3) << "foot at " << p.transpose();
    }
    EXPECT_EQ(feet, 8);
  }
}

TEST_F(GroundTest, RoughGroundSpreadsTheOutcomesOfOneCommand) {
  // Zero sensor noise: on the plane, the same command from different places gives the same
  // displacement; on rough ground it does not.
  const auto spread = [](const SimConfig& c) {
    Simulator sim(c);
    double lo = 1e9, hi = -1e9;
    for (const double x : {-0.6, -0.2, 0.2, 0.6}) {
      EXPECT_EQ(sim.Place(x, 0.3 * x, 0), RunOutcome::kCompleted);
      const Pose start = sim.TorsoPose();
      EXPECT_EQ(sim.RunCommand({0.5, 0, 0}), RunOutcome::kCompleted);
      const double yaw = DeltaPoseBody(start, sim.TorsoPose())[5];
      lo = std::min(lo, yaw);
      hi = std::max(hi, yaw);
    }
    return hi - lo;
  };
  SimConfig plane;
  plane.slope_deg = 0;
  plane.noise = NoiseConfig{0, 0, 0, 0, 0, 0};
  SimConfig rough = plane;
  rough.terrain = Stony();
  const double flat = spread(plane), bumpy = spread(rough);
  EXPECT_LT(flat, 1e-4);
  EXPECT_GT(bumpy, 20 * std::max(flat, 1e-4));
}

TEST_F(GroundTest, AnyRobotFromItsOwnFolderWalksOnRoughGround) {
  // The hexapod's MJCF is compiled from its folder inside the ground wrapper.
  SimConfig c = LoadSimConfig((fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots" / "hexapod.json").string());
  c.slope_deg = 0;
  TerrainDescription t = Stony();
  t.stones.height_m = 0.02;
  c.terrain = t;
  Simulator sim(c);
  ASSERT_EQ(sim.Place(0.1, -0.2, 0), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand({0.5, 0, 0}), RunOutcome::kCompleted);
  EXPECT_GT(DeltaPoseBody(start, sim.TorsoPose())[0], 0.05);
}

// Level ground is a plane facing up: no slope, no height field; plane ground allows the slope (the
// posture check of lib/sim2real/posture.h compares z directly on the first, radially on the second,
// and not at all on a height field).
TEST_F(GroundTest, LevelGroundIsAPlaneWithoutSlopeOrHeights) {
  SimConfig c = LoadSimConfig((fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots" / "hexapod.json").string());
  EXPECT_FALSE(Simulator(c).LevelGround()) << "the hexapod's 10 degree slope";
  EXPECT_TRUE(Simulator(c).PlaneGround()) << "the hexapod's 10 degree slope";
  c.slope_deg = 0;
  EXPECT_TRUE(Simulator(c).LevelGround());
  EXPECT_TRUE(Simulator(c).PlaneGround());
  c.terrain = Stony();
  EXPECT_FALSE(Simulator(c).LevelGround()) << "a height field";
  EXPECT_FALSE(Simulator(c).PlaneGround()) << "a height field";
}

TEST_F(GroundTest, MissingRobotFileIsNamed) {
  SimConfig c = OnGround(Stony());
  c.mjcf_path = "/nonexistent/robot.xml";
  try {
    Ground(c).Load(c);
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/robot.xml"), std::string::npos) << e.what();
  }
}


TEST(GroundScaleTest, TheSimulatorWarnsOfGroundOffItsRobotsScale) {
  SimConfig c;
  TerrainDescription t;
  t.half_size_m = 2.0;
  t.resolution_m = 0.04;
  t.stones = {0.04, 0.08, 1};
  c.terrain = t;
  EXPECT_TRUE(Simulator(c).RobotWarnings().empty());
  c.terrain->steps = {0.12, 0.5};  // most of the octopod's 0.14 m stance
  const auto warnings = Simulator(c).RobotWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("stance height of 0.14"), std::string::npos) << warnings[0];
  EXPECT_TRUE(Simulator(SimConfig{}).RobotWarnings().empty());
}

}  // namespace
}  // namespace dgmm::sim
