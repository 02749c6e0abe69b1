// Steps a robot's legs cannot make (lib/sim/gait_reach.h): the planar quadruped, whose legs have a
// hip pitch and a knee only (they move their feet in one plane), against the project's
// hexapod, sprawled quadruped and scorpion (robot blocks), whose legs reach every step of their gaits.
#include "sim/gait_reach.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include "sim/legged_robot.h"
#include "sim/mujoco_model.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"
#include "robot_files.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

using test::kRobots;

struct Bound {
  MjModelPtr model;
  LeggedRobot robot;
};
Bound Bind(const SimConfig& c) {
  Bound b{LoadRobotModel(c), {}};
  b.robot = BindRobot(b.model.get(), *c.robot, c.mjcf_path);
  return b;
}

// The largest miss relative to the travel among a command axis's misses (0 forward, 1 lateral, 2 turn).
double WorstShare(const std::vector<GaitMiss>& misses, int axis) {
  double worst = 0;
  for (const GaitMiss& m : misses) {
    if (m.command[axis] != 0) worst = std::max(worst, m.residual_m / m.travel_m);
  }
  return worst;
}

// datasets/robots/planar_quadruped.json: four legs under a box body, each a hip pitch and a knee.
SimConfig PlanarQuadruped() { return LoadSimConfig((kRobots / "planar_quadruped.json").string()); }

TEST(GaitReach, LegsMovingInOnePlaneMissTheirSidewaysAndTurningSteps) {
  const SimConfig c = PlanarQuadruped();
  const Bound b = Bind(c);
  const std::vector<GaitMiss> misses = MeasureGaitMisses(b.model.get(), b.robot, c.robot->gait.turn_rad);
  ASSERT_EQ(misses.size(), 6u * 4u);  // 3 axes x 2 signs x 4 legs
  EXPECT_LT(WorstShare(misses, 0), 0.05);  // forward and back: in the legs' plane
  // No sideways joint: the foot stays at its stance point, half its travel from either end.
  EXPECT_NEAR(WorstShare(misses, 1), 0.5, 0.05);
  EXPECT_GT(WorstShare(misses, 2), 0.25);
  const std::vector<std::string> warnings = GaitReachWarnings(misses, b.robot);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("lateral +, lateral -, turn +, turn -"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find("forward"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("legs fl, fr, hl, hr"), std::string::npos) << warnings[0];
}

TEST(GaitReach, TheSimulatorWarnsBeforeAnythingIsRecorded) {
  const Simulator sim(PlanarQuadruped());
  const std::vector<std::string> warnings = sim.RobotWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0].rfind("robot.gait: ", 0), 0u) << warnings[0];
}

TEST(GaitReach, TheProjectsRobotsFollowEveryStepOfTheirGaits) {
  for (const char* name : {"hexapod.json", "sprawled_quadruped.json", "scorpion_generic.json"}) {
    const SimConfig c = LoadSimConfig((kRobots / name).string());
    const Bound b = Bind(c);
    const std::vector<GaitMiss> misses = MeasureGaitMisses(b.model.get(), b.robot, c.robot->gait.turn_rad);
    for (int axis = 0; axis < 3; ++axis) EXPECT_LT(WorstShare(misses, axis), 0.05) << name << " axis " << axis;
    EXPECT_TRUE(GaitReachWarnings(misses, b.robot).empty()) << name;
  }
}

// The hexapod whose hip-yaw servos can be commanded to +-0.05 rad only (ctrlrange): its feet swing
// fore and aft through the hip yaw, so forward steps and turns cannot be made, and the gait asks for
// no more than the servos can be told (until 2026-12-03 MuJoCo clipped the gait's targets silently).
TEST(GaitReach, AServosCtrlRangeBoundsTheGaitsTargets) {
  std::string xml;
  {
    std::ifstream in(kRobots / "hexapod.xml");
    xml.assign(std::istreambuf_iterator<char>(in), {});
  }
  int narrowed = 0;
  for (auto at = xml.find("_hip_yaw\" joint="); at != std::string::npos; at = xml.find("_hip_yaw\" joint=", at + 1)) {
    const auto end = xml.find("/>", at);
    xml.insert(end, " ctrllimited=\"true\" ctrlrange=\"-0.05 0.05\"");
    ++narrowed;
  }
  ASSERT_EQ(narrowed, 6);
  const fs::path path = fs::temp_directory_path() / ("dgmm_yaw_range_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig c = LoadSimConfig((kRobots / "hexapod.json").string());
  c.mjcf_path = path.string();
  const Bound b = Bind(c);
  fs::remove(path);
  for (const LegChain& leg : b.robot.legs) {
    EXPECT_NEAR(leg.q_hi[0], 0.05, 1e-12) << leg.name;  // the hip yaw: its servo's range, not the joint's
    EXPECT_NEAR(leg.q_lo[0], -0.05, 1e-12) << leg.name;
  }
  const std::vector<GaitMiss> misses = MeasureGaitMisses(b.model.get(), b.robot, c.robot->gait.turn_rad);
  EXPECT_GT(WorstShare(misses, 0), 0.25);
  const std::vector<std::string> warnings = GaitReachWarnings(misses, b.robot);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("forward +"), std::string::npos) << warnings[0];
}

TEST(GaitReachWarnings, OnlyMissesOverTheShareOfTheTravelCount) {
  LeggedRobot robot;
  robot.legs.resize(2);
  robot.legs[0].name = "a", robot.legs[1].name = "b";
  const GaitMiss forward{Eigen::Vector3d(1, 0, 0), 0, 0.002, 0.04};
  const std::vector<GaitMiss> small = {forward, {Eigen::Vector3d(0, -1, 0), 1, 0.009, 0.04}};
  EXPECT_TRUE(GaitReachWarnings(small, robot).empty());
  const std::vector<GaitMiss> big = {forward, {Eigen::Vector3d(0, -1, 0), 1, 0.012, 0.04}};
  const std::vector<std::string> w = GaitReachWarnings(big, robot);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("(lateral -; legs b)"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("30%"), std::string::npos) << w[0];
}

}  // namespace
}  // namespace dgmm::sim
