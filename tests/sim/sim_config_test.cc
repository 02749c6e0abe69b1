#include "sim/sim_config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace dgmm::sim {
namespace {

TEST(SimConfigTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(SimConfig{}.IsValid(&error)) << error;
}

TEST(SimConfigTest, JsonRoundTripKeepsEveryField) {
  SimConfig c;
  c.slope_deg = 12.5;
  c.friction.sliding = 0.6;
  c.masses.torso_kg = 7.25;
  c.payload.mass_kg = 1.5;
  c.payload.position_body_m = Eigen::Vector3d(0.05, -0.1, 0.06);
  c.actuators.leg_gain[3] = 0.4;
  c.actuators.latency_s = 0.03;
  c.actuators.backlash_rad = 0.05;
  c.noise.imu_roll_sd_rad = 0.02;
  c.mjcf_path = "/tmp/robot.xml";
  c.names.torso_body = "body";
  c.placement_half_width_m = 0.75;
  const SimConfig back = SimConfigFromJson(SimConfigToJson(c), "test");
  EXPECT_DOUBLE_EQ(back.placement_half_width_m, 0.75);
  EXPECT_EQ(SimConfigToJson(SimConfig()).find("placement_half_width_m"), std::string::npos);  // shipped sets' configs
  EXPECT_EQ(SimConfigToJson(back), SimConfigToJson(c));
  EXPECT_DOUBLE_EQ(back.payload.position_body_m.y(), -0.1);
  EXPECT_DOUBLE_EQ(back.actuators.leg_gain[3], 0.4);
  EXPECT_DOUBLE_EQ(back.actuators.latency_s, 0.03);
  EXPECT_DOUBLE_EQ(back.actuators.backlash_rad, 0.05);
  EXPECT_EQ(back.names.torso_body, "body");
}

TEST(SimConfigTest, MissingFieldsKeepDefaults) {
  const SimConfig c = SimConfigFromJson(R"({"slope_deg": 5, "friction": {"sliding": 0.4}})", "t");
  EXPECT_DOUBLE_EQ(c.slope_deg, 5);
  EXPECT_DOUBLE_EQ(c.friction.sliding, 0.4);
  EXPECT_DOUBLE_EQ(c.friction.torsional, FrictionConfig{}.torsional);
  EXPECT_DOUBLE_EQ(c.timestep_s, SimConfig{}.timestep_s);
}

// Each bad input must be rejected with an InputError naming the field.
TEST(SimConfigTest, RejectsBadInputNamingTheField) {
  const std::pair<const char*, const char*> cases[] = {
      {"{not json", "not valid JSON"},
      {R"({"slope": 3})", "slope"},
      {R"({"friction": {"slidng": 1}})", "friction.slidng"},
      {R"({"slope_deg": "steep"})", "slope_deg"},
      {R"({"slope_deg": 80})", "slope_deg"},
      {R"({"actuators": {"leg_gain": [1, 1]}})", "actuators.leg_gain"},
      {R"({"actuators": {"leg_gain": [1, 1, 1, 1, 1, 1, 1, 0]}})", "leg_gain"},
      {R"({"masses": {"torso_kg": -1}})", "masses"},
      {R"({"actuators": {"latency_s": 0.3}})", "actuators.latency_s"},
      {R"({"actuators": {"latency_s": -0.01}})", "actuators.latency_s"},
      {R"({"actuators": {"backlash_rad": 0.25}})", "actuators.backlash_rad"},
      {R"({"actuators": {"backlash_rad": -0.01}})", "actuators.backlash_rad"},
      {R"({"command_duration_s": 1.2})", "command_duration_s"},
      {R"({"timestep_s": 0})", "timestep_s"},
      {R"([1, 2])", "object"},
  };
  for (const auto& [text, field] : cases) {
    try {
      SimConfigFromJson(text, "cfg.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("cfg.json"), std::string::npos) << e.what();
    }
  }
}

// An actuator's latency may be up to a third of the gait's cycle, 0.2 s at the least: a robot
// whose cycle is 1.2 s (four times the hexapod's size) may lag 0.4 s, the built-in robot 0.2 s.
TEST(SimConfigTest, TheLongestLatencyFollowsTheGaitsCycle) {
  SimConfig builtin;
  EXPECT_DOUBLE_EQ(MaxLatencyS(builtin), 0.2);
  SimConfig slow;
  slow.robot = RobotDescription{};
  slow.robot->gait.period_s = 1.2;
  EXPECT_NEAR(MaxLatencyS(slow), 0.4, 1e-12);
  std::string error;
  slow.actuators.latency_s = 0.3;
  EXPECT_TRUE(slow.IsValid(&error) || error.find("latency") == std::string::npos) << error;
  slow.actuators.latency_s = 0.45;
  EXPECT_FALSE(slow.IsValid(&error));
  EXPECT_NE(error.find("actuators.latency_s: expected a value in [0, 0.4] s"), std::string::npos) << error;
}

TEST(SimConfigTest, SaveAndLoadResolvesRelativeMjcf) {
  const auto dir = std::filesystem::temp_directory_path() / "dgmm_sim_config_test";
  std::filesystem::create_directories(dir);
  SimConfig c;
  c.mjcf_path = "robot.xml";
  SaveSimConfig(c, (dir / "cfg.json").string());
  const SimConfig back = LoadSimConfig((dir / "cfg.json").string());
  EXPECT_EQ(std::filesystem::path(back.mjcf_path), dir / "robot.xml");
  EXPECT_THROW(LoadSimConfig((dir / "absent.json").string()), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dgmm::sim
