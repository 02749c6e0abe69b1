// The gait's servo feedforward (lib/sim/servo_feedforward.h): the loads on the feet balance the
// weight (closed forms), a foot in the air carries nothing, and soft servos hold their targets under
// the robot's weight with it, while what the controller does not know (a payload) still shows.
#include "sim/servo_feedforward.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <random>
#include <unistd.h>

#include "sim/generic_walker.h"
#include "sim/ground.h"
#include "sim/mujoco_model.h"
#include "sim/robot_description.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"
#include "robot_files.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

TEST(SupportForces, FourFeetAroundTheCentreCarryAQuarterEach) {
  const std::vector<Eigen::Vector2d> feet = {{1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  const Eigen::VectorXd f = SupportForces(feet, {1, 1, 1, 1}, Eigen::Vector2d::Zero(), 100);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(f[i], 25, 1e-9);
}

// Three feet: the loads are the centre's barycentric coordinates times the weight (one solution).
TEST(SupportForces, ThreeFeetCarryTheCentresBarycentricShares) {
  std::mt19937 rng(1027);
  std::uniform_real_distribution<double> u(-1, 1), w(0.05, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<Eigen::Vector2d> feet = {{u(rng), u(rng)}, {u(rng), u(rng)}, {u(rng), u(rng)}};
    Eigen::Vector3d bary(w(rng), w(rng), w(rng));
    bary /= bary.sum();
    const Eigen::Vector2d centre = bary[0] * feet[0] + bary[1] * feet[1] + bary[2] * feet[2];
    const Eigen::VectorXd f = SupportForces(feet, {1, 1, 1}, centre, 50);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(f[i], 50 * bary[i], 1e-6) << "trial " << trial;
  }
}

TEST(SupportForces, ASwingingFootCarriesNothingAndTwoFeetShareByTheLever) {
  const std::vector<Eigen::Vector2d> feet = {{1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  // The trot's diagonal pair (front left, rear right) with the centre a quarter of the way along it.
  const Eigen::Vector2d centre(0.5, 0.5);
  const Eigen::VectorXd f = SupportForces(feet, {1, 0, 0, 1}, centre, 40);
  EXPECT_EQ(f[1], 0);
  EXPECT_EQ(f[2], 0);
  EXPECT_NEAR(f[0], 30, 1e-9);  // the foot nearer the centre: 3/4 of the weight
  EXPECT_NEAR(f[3], 10, 1e-9);
}

// A boolean, written only when on, and refused beside a replayed controller (which it would not touch).
TEST(ServoFeedforward, TheConfigFieldIsABooleanWrittenOnlyWhenOn) {
  SimConfig c = LoadSimConfig((test::kRobots / "hexapod.json").string());
  EXPECT_FALSE(c.robot->gait.servo_feedforward);
  EXPECT_EQ(SimConfigToJson(c).find("servo_feedforward"), std::string::npos);  // older configs' text unchanged
  c.robot->gait.servo_feedforward = true;
  EXPECT_TRUE(SimConfigFromJson(SimConfigToJson(c), "round trip").robot->gait.servo_feedforward);
  try {
    RobotDescriptionFromJson(R"({"torso_body": "t", "floor_geom": "f", "legs": [{"name": "a", "joints": ["j"],
                                 "foot": {"geom": "g"}}], "gait": {"servo_feedforward": "yes"}})",
                             "cfg.json");
    FAIL() << "a string accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("robot.gait.servo_feedforward: expected true or false"), std::string::npos)
        << e.what();
  }
  const std::string replay =
      test::ReadText(test::kRobots / "mammal_quadruped" / "mammal_quadruped.json");
  const auto robot = nlohmann::json::parse(replay)["robot"];
  auto with = robot;
  with["gait"]["servo_feedforward"] = true;
  try {
    RobotDescriptionFromJson(with.dump(), "mammal.json");
    FAIL() << "a replay with the gait's feedforward accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mammal.json: robot.gait.servo_feedforward: the generic gait's option"),
              std::string::npos)
        << e.what();
  }
}

// The hexapod on flat ground with its servos' kp cut from 80 to 10 (a soft robot of our own).
SimConfig SoftHexapod(const fs::path& path) {
  std::string xml = test::ReadText(test::kRobots / "hexapod.xml");
  const std::string from = R"(position kp="80")";
  xml.replace(xml.find(from), from.size(), R"(position kp="10")");
  std::ofstream(path) << xml;
  SimConfig c = LoadSimConfig((test::kRobots / "hexapod.json").string());
  c.mjcf_path = path.string();
  c.slope_deg = 0;
  return c;
}

// The largest |q - target| over the legs' joints after standing: how far the servos give.
double StandingServoError(const SimConfig& c) {
  const Ground plane(c);
  GenericWalker walker(c, LoadRobotModel(c), plane, "soft hexapod");
  walker.Start();
  EXPECT_EQ(walker.Place(0, 0, 0), RunOutcome::kCompleted);
  walker.Stand(0.5);
  double worst = 0;
  for (const LegChain& leg : walker.robot().legs) {
    for (std::size_t k = 0; k < leg.qpos.size(); ++k) {
      worst = std::max(worst, std::abs(walker.data()->qpos[leg.qpos[k]] - leg.stance_q[k]));
    }
  }
  return worst;
}

TEST(ServoFeedforward, SoftServosHoldTheirTargetsUnderTheWeightAndAPayloadStillShows) {
  const fs::path path = fs::temp_directory_path() / ("dgmm_soft_hexapod_" + std::to_string(::getpid()) + ".xml");
  SimConfig c = SoftHexapod(path);
  const double without = StandingServoError(c);
  c.robot->gait.servo_feedforward = true;
  const double with = StandingServoError(c);
  c.payload.mass_kg = 1.5;  // half the robot's mass, unknown to the controller
  const double loaded = StandingServoError(c);
  fs::remove(path);
  std::printf("standing servo error: %.4g rad without, %.4g with, %.4g with a payload\n", without, with, loaded);
  EXPECT_LT(with, 0.3 * without) << "without " << without << " rad, with " << with;
  EXPECT_GT(loaded, 2 * with) << "with " << with << " rad, with the payload " << loaded;
}

}  // namespace
}  // namespace dgmm::sim
