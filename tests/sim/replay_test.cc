// A robot driven by replayed actuator signals (robot.controller type replay: lib/sim/replay.h,
// generic_walker.h; the actuation line both controllers share is tested in actuation_line_test.cc),
// on the project's mammal-shaped quadruped (datasets/robots/mammal_quadruped) and small variants.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "sim/generic_walker.h"
#include "sim/ground.h"
#include "sim/protocol.h"
#include "sim/replay.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

const fs::path kMammal = fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots" / "mammal_quadruped";

SimConfig Mammal() { return LoadSimConfig((kMammal / "mammal_quadruped.json").string()); }

// A scratch folder removed at the end of the test.
struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("dgmm_replay_" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() { fs::remove_all(dir); }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(ReplayTrack, InterpolatesLinearlyAndRepeatsWithTheRecordingsLength) {
  Eigen::MatrixXd v(3, 2);
  v << 0, 10, 1, 20, 3, 10;
  const ReplayTrack track({0, 0.1, 0.3}, v);
  EXPECT_NEAR(track.At(0.05)[0], 0.5, 1e-12);
  EXPECT_NEAR(track.At(0.2)[1], 15, 1e-12);
  EXPECT_NEAR(track.At(0.3 + 0.05)[0], 0.5, 1e-12);  // the next period
  EXPECT_DOUBLE_EQ(track.period_s(), 0.3);
}

TEST(ReplayTrack, BadFilesAreRefusedNamingFileLineAndColumn) {
  Scratch s;
  const std::vector<std::string> actuators = {"a", "b"};
  EXPECT_NO_THROW(LoadReplayTrack(s.Write("ok.csv", "t,b,a\n0,1,2\n0.5,3,4\n"), actuators));
  const ReplayTrack ok = LoadReplayTrack(s.Write("ok.csv", "t,b,a\n0,1,2\n0.5,3,4\n"), actuators);
  EXPECT_DOUBLE_EQ(ok.At(0)[0], 2);  // columns in the order of the actuators, not the file
  auto expect = [&](const std::string& text, const std::string& part) {
    const std::string error = ErrorOf([&] { LoadReplayTrack(s.Write("bad.csv", text), actuators); });
    EXPECT_NE(error.find(part), std::string::npos) << "expected \"" << part << "\" in: " << error;
    EXPECT_NE(error.find("bad.csv"), std::string::npos) << error;
  };
  expect("t,a\n0,1\n1,2\n", "column 'b'");
  expect("t,a,b,c\n0,1,2,3\n1,2,3,4\n", "one column per actuator");
  expect("t,a,b\n0.1,1,2\n1,2,3\n", "first time to be 0");
  expect("t,a,b\n0,1,2\n0,2,3\n", "line 3");
  expect("t,a,b\n0,1,2\n1,x,3\n", "line 3");
  expect("t,a,b\n0,1,2\n", "at least two rows");
}

TEST(ReplayConfig, TheControllerBlockIsReadStrictlyAndRoundTrips) {
  const SimConfig c = Mammal();
  ASSERT_TRUE(c.robot->controller.replay());
  EXPECT_EQ(c.robot->controller.recordings.size(), 27u);
  EXPECT_TRUE(fs::path(c.robot->controller.recordings[0].file).is_absolute()) << "paths are resolved beside the config";
  const RobotDescription back = RobotDescriptionFromJson(RobotDescriptionToJson(*c.robot), "round trip");
  EXPECT_EQ(back.controller.recordings.size(), 27u);
  EXPECT_EQ(back.controller.signal, "position");
  auto error = [](const std::string& controller) {
    return ErrorOf([&] {
      RobotDescriptionFromJson(R"({"legs": [{"name": "a", "joints": ["j"], "foot": {"site": "f"}}], "controller": )" +
                                   controller + "}",
                               "r.json");
    });
  };
  EXPECT_NE(error(R"({"type": "mpc"})").find("robot.controller.type"), std::string::npos);
  EXPECT_NE(error(R"({"type": "replay"})").find("robot.controller.recordings"), std::string::npos);
  EXPECT_NE(error(R"({"type": "replay", "signal": "voltage", "recordings": []})").find("robot.controller.signal"),
            std::string::npos);
  EXPECT_NE(error(R"({"type": "replay", "recordings": [{"command": [0,0,0], "file": "a.csv"},
                                                       {"command": [0,0,0], "file": "b.csv"}]})")
                .find("recordings[1].command"),
            std::string::npos);
  EXPECT_NE(error(R"({"type": "gait", "recordings": [{"command": [0,0,0], "file": "a.csv"}]})").find("only with type replay"),
            std::string::npos);
}

TEST(Replay, TheMammalQuadrupedWalksItsRecordedTrot) {
  Simulator sim(Mammal());
  const RobotDescription& r = *sim.config().robot;
  const double cycles = sim.config().command_duration_s / r.gait.period_s;
  ASSERT_EQ(sim.leg_count(), 4);
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0, 0.5, 0)), RunOutcome::kCompleted);
  const Eigen::Vector3d moved = start.rotation.transpose() * (sim.TorsoPose().position_m - start.position_m);
  EXPECT_NEAR(moved.y() / (0.5 * r.gait.stride_m * cycles), 1.0, 0.25);
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose before = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0, 0, 0.5)), RunOutcome::kCompleted);
  const Eigen::Matrix3d turn = before.rotation.transpose() * sim.TorsoPose().rotation;
  EXPECT_NEAR(std::atan2(turn(1, 0), turn(0, 0)) / (0.5 * r.gait.turn_rad * cycles), 1.0, 0.3);
}

TEST(Replay, TheMammalQuadrupedStandsAndTurnsAcrossTheSlope) {
  // Facing across the 10 degree slope (the paper protocol's theta = 0), where the first replay
  // (paws under the shoulders) rolled over downhill while standing and every turn fell.
  SimConfig c = Mammal();
  c.slope_deg = 10;
  Simulator sim(c);
  const double across = std::acos(-1.0) / 2;
  ASSERT_EQ(sim.Place(0, 0, across), RunOutcome::kCompleted);
  EXPECT_EQ(sim.RunCommand(Eigen::Vector3d::Zero()), RunOutcome::kCompleted) << "standing";
  for (const double turn : {0.5, -0.5, 0.5}) {
    const Pose before = sim.TorsoPose();
    ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0, 0, turn)), RunOutcome::kCompleted) << "turn " << turn;
    const Eigen::Matrix3d r = before.rotation.transpose() * sim.TorsoPose().rotation;
    EXPECT_GT(std::atan2(r(1, 0), r(0, 0)) * turn, 0) << "turns the commanded way";
  }
  EXPECT_GT(sim.TorsoPose().rotation(2, 2), std::cos(20 * std::acos(-1.0) / 180)) << "upright within 20 degrees";
}

TEST(Replay, BadReplaysAreRefusedNamingThePart) {
  auto expect = [](const std::string& error, const std::string& part) {
    EXPECT_NE(error.find(part), std::string::npos) << "expected \"" << part << "\" in: " << error;
  };
  SimConfig no_stand = Mammal();
  no_stand.robot->controller.recordings.erase(no_stand.robot->controller.recordings.begin());
  expect(ErrorOf([&] { Simulator sim(no_stand); }), "command [0, 0, 0]");
  SimConfig torque = Mammal();
  torque.robot->controller.signal = "torque";
  expect(ErrorOf([&] { Simulator sim(torque); }), "is a position servo");
  // The protocol needs a recording of every command it runs: refused before anything is simulated.
  SimConfig missing = Mammal();
  missing.robot->controller.recordings.pop_back();
  expect(ErrorOf([&] { SimulateProtocol(missing, ProtocolOptions{}); }), "no recording of command [0.5, 0.5, 0.5]");
  // The generic gait refuses what only a replay can drive.
  SimConfig gait = Mammal();
  gait.robot->controller = ControllerDescription{};
  EXPECT_EQ(ErrorOf([&] { Simulator sim(gait); }), "") << "position servos on every leg joint: the gait can drive it";
}

TEST(Replay, TorquesGoToMotorsThroughTheLatency) {
  // The mammal with motors instead of servos, a torque recording and a latency of 5 steps.
  Scratch s;
  std::ifstream in(kMammal / "mammal_quadruped.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string servo_default = "<position kp=\"120\" ";
  ASSERT_NE(xml.find(servo_default), std::string::npos);
  xml.replace(xml.find(servo_default), servo_default.size(), "<motor ");
  for (std::size_t at; (at = xml.find("<position ")) != std::string::npos;) xml.replace(at, 10, "<motor ");
  SimConfig c = Mammal();
  c.mjcf_path = s.Write("motors.xml", xml);
  std::string header = "t", row0 = "0", row1 = "1", zeros = "1";
  for (const auto& leg : c.robot->legs) {
    for (const auto& j : {"_abduction_servo", "_hip_servo", "_knee_servo"}) {
      header += "," + leg.name + j;
      row0 += ",0";
      row1 += ",2";
      zeros += ",0";
    }
  }
  const std::string stand = s.Write("stand.csv", header + "\n" + row0 + "\n" + zeros + "\n");
  const std::string file = s.Write("torques.csv", header + "\n" + row0 + "\n" + row1 + "\n");
  c.robot->controller.signal = "torque";
  c.robot->controller.recordings = {{Eigen::Vector3d::Zero(), stand}, {Eigen::Vector3d(0.5, 0, 0), file}};
  c.actuators.latency_s = 5 * c.timestep_s;
  MjModelPtr model = LoadRobotModel(c);
  const Ground plane(c);
  GenericWalker walker(c, std::move(model), plane, "motors");
  walker.Start();
  walker.Place(0, 0, 0);
  std::vector<double> ctrl;
  walker.Run(Eigen::Vector3d(0.5, 0, 0), [&](int) { ctrl.push_back(walker.data()->ctrl[0]); });
  ASSERT_GT(ctrl.size(), 20u);
  // Step s sends 2 (s + 1) dt (a ramp from 0 to 2 over 1 s); the motor sees it 5 steps later.
  const double dt = c.timestep_s;
  EXPECT_EQ(ctrl[3], 0.0);  // still what the stand sent
  EXPECT_NEAR(ctrl[10], 2 * (10 - 5 + 1) * dt, 1e-9);
  EXPECT_NEAR(ctrl[20], 2 * (20 - 5 + 1) * dt, 1e-9);
}

}  // namespace
}  // namespace dgmm::sim
