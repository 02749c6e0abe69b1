// Signals on their way to the actuators (lib/sim/actuation_line.h): joint targets reach a servo as
// the ctrl at which it holds its joint there, whatever its gear or affine parameters; other
// actuators get the signal as it is.
#include "sim/actuation_line.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "sim/mujoco_model.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

TEST(ActuationLine, DelaysBySteppingAndAppliesTheDeadBandToJointServos) {
  const char* xml = R"(<mujoco><worldbody><body><joint name="j" type="hinge"/><geom size="0.1"/></body></worldbody>
    <actuator><position name="servo" joint="j" kp="10"/><motor name="motor" joint="j"/></actuator></mujoco>)";
  MjModelPtr model = LoadMjcfString(xml, "line");
  MjDataPtr data(mj_makeData(model.get()));
  ActuationLine line(model.get(), {0, 1}, 2, 0.2);
  line.Reset(Eigen::Vector2d(0.0, 0.0));
  line.Send(Eigen::Vector2d(1.0, 5.0));
  line.Write(data.get());
  EXPECT_DOUBLE_EQ(data->ctrl[1], 0.0);  // two steps of latency: not yet
  line.Send(Eigen::Vector2d(1.0, 5.0));
  line.Write(data.get());
  EXPECT_DOUBLE_EQ(data->ctrl[1], 0.0);
  line.Send(Eigen::Vector2d(1.0, 5.0));
  line.Write(data.get());
  EXPECT_DOUBLE_EQ(data->ctrl[1], 5.0);  // the motor's torque passes unchanged
  EXPECT_DOUBLE_EQ(data->ctrl[0], 0.9);  // the servo's target, q = 0, less half the backlash
}

// Four hinges on one body, each driven by another kind of actuator.
constexpr char kFourActuators[] = R"(<mujoco><worldbody><body>
  <joint name="a" axis="0 1 0"/><joint name="b" axis="0 1 0"/>
  <joint name="c" axis="0 1 0"/><joint name="d" axis="1 0 0"/>
  <geom type="sphere" size="0.1" mass="1"/></body></worldbody><actuator>
  <position joint="a" kp="20"/>
  <position joint="b" kp="20" gear="2"/>
  <general joint="c" gaintype="fixed" gainprm="10" biastype="affine" biasprm="1 -20 0"/>
  <motor joint="d"/>
</actuator></mujoco>)";

TEST(ActuationLine, AServoGetsTheCtrlThatHoldsItsJointAtTheTarget) {
  MjModelPtr m = LoadMjcfString(kFourActuators, "four actuators");
  MjDataPtr d(mj_makeData(m.get()));
  ActuationLine line(m.get(), {0, 1, 2, 3}, 0, 0.0);
  line.Reset(Eigen::Vector4d(0.3, 0.3, 0.3, 0.3));
  line.Write(d.get());
  EXPECT_EQ(d->ctrl[0], 0.3);                          // kp (ctrl - q): ctrl = q, bit for bit
  EXPECT_DOUBLE_EQ(d->ctrl[1], 0.6);                   // kp (ctrl - 2 q): ctrl = 2 q
  EXPECT_DOUBLE_EQ(d->ctrl[2], -(1 - 20 * 0.3) / 10);  // 10 ctrl + 1 - 20 q = 0
  EXPECT_EQ(d->ctrl[3], 0.3);                          // a motor's torque passes as it is
}

// The hexapod with every servo geared 2:1 (kp 20 and force range 10 at the actuator: the same
// 80 Nm/rad and 20 Nm at the joint) walks as the hexapod does. Until 2026-12-03 the gait sent
// joint angles as ctrl, and a geared robot took half steps (0.036 m of mean travel for 0.073).
TEST(ActuationLine, AGearedRobotWalksAsItsUngearedTwin) {
  const fs::path robots = fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots";
  std::stringstream text;
  text << std::ifstream(robots / "hexapod.xml").rdbuf();
  std::string xml = text.str();
  const std::string servo = R"(<position kp="80" forcerange="-20 20" forcelimited="true"/>)";
  ASSERT_NE(xml.find(servo), std::string::npos);
  const std::string geared_servo = R"(<position kp="20" gear="2" forcerange="-10 10" forcelimited="true"/>)";
  xml.replace(xml.find(servo), servo.size(), geared_servo);
  const fs::path path = fs::temp_directory_path() / ("dgmm_geared_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig geared = LoadSimConfig((robots / "hexapod.json").string());
  const SimConfig plain = geared;
  geared.mjcf_path = path.string();
  Simulator a(plain), b(geared);
  fs::remove(path);
  for (Simulator* sim : {&a, &b}) {
    ASSERT_EQ(sim->Place(0, 0, 0), RunOutcome::kCompleted);
    ASSERT_EQ(sim->RunCommand(Eigen::Vector3d(0.5, 0, 0)), RunOutcome::kCompleted);
  }
  const double travel = a.TorsoPose().position_m.x();
  EXPECT_NEAR(b.TorsoPose().position_m.x(), travel, 0.05 * std::abs(travel));
}

}  // namespace
}  // namespace dgmm::sim
