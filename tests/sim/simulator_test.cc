#include "sim/simulator.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "mujoco_fixture.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

using SimulatorTest = test::MujocoTest;
using Vec6 = Eigen::Matrix<double, 6, 1>;

constexpr double kUphill = 0, kAcross = M_PI / 2, kDownhill = M_PI;

// Displacement of one execution of `command` from a fresh placement.
Vec6 RunOnce(Simulator& sim, const Eigen::Vector3d& command, double heading = 0) {
  EXPECT_EQ(sim.Place(0, 0, heading), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  EXPECT_EQ(sim.RunCommand(command), RunOutcome::kCompleted);
  return DeltaPoseBody(start, sim.TorsoPose());
}

SimConfig Flat() {
  SimConfig c;
  c.slope_deg = 0;
  return c;
}

// Nominal speed: stride_m per half period at |command| = 1; commands of 0.5 over 1.5 s should
// cover 0.36 m if nothing slipped. The thresholds below ask for well over half of that.
constexpr double kMinTravelM = 0.2;
constexpr double kMaxCrossTravelM = 0.05;  // sideways leak of a straight command on flat ground
constexpr double kMinTurnRad = 0.25;       // nominal 0.45 rad

TEST_F(SimulatorTest, BuiltInRobotHasDocumentedMass) {
  Simulator sim(Flat());
  const MassConfig m;
  EXPECT_NEAR(sim.total_mass_kg(), m.torso_kg + 8 * (m.coxa_kg + m.femur_kg + m.tibia_kg), 1e-3);
  SimConfig heavy = Flat();
  heavy.payload.mass_kg = 2;
  EXPECT_NEAR(Simulator(heavy).total_mass_kg(), sim.total_mass_kg() + 2, 1e-3);
}

TEST_F(SimulatorTest, WalksForwardSidewaysAndTurnsOnFlatGround) {
  Simulator sim(Flat());
  const Vec6 fwd = RunOnce(sim, {0.5, 0, 0});
  EXPECT_GT(fwd[0], kMinTravelM);
  EXPECT_LT(std::abs(fwd[1]), kMaxCrossTravelM);
  const Vec6 back = RunOnce(sim, {-0.5, 0, 0});
  EXPECT_LT(back[0], -kMinTravelM);
  const Vec6 left = RunOnce(sim, {0, 0.5, 0});
  EXPECT_GT(left[1], kMinTravelM);
  EXPECT_LT(std::abs(left[0]), kMaxCrossTravelM);
  const Vec6 right = RunOnce(sim, {0, -0.5, 0});
  EXPECT_LT(right[1], -kMinTravelM);
  const Vec6 ccw = RunOnce(sim, {0, 0, 0.5});
  EXPECT_GT(ccw[5], kMinTurnRad);
  EXPECT_LT(ccw.head<2>().norm(), kMaxCrossTravelM);
  EXPECT_LT(RunOnce(sim, {0, 0, -0.5})[5], -kMinTurnRad);
  // A full command goes further than a half one.
  EXPECT_GT(RunOnce(sim, {1, 0, 0})[0], 1.5 * fwd[0]);
}

TEST_F(SimulatorTest, WalksOnTheSlopeInEveryHeading) {
  Simulator sim{SimConfig{}};
  for (double heading : {kUphill, kAcross, kDownhill, -kAcross}) {
    SCOPED_TRACE(heading);
    const double kSlopeTravelM = 0.1;  // downhill slip eats up to half the stride uphill
    EXPECT_GT(RunOnce(sim, {0.5, 0, 0}, heading)[0], kSlopeTravelM);
    EXPECT_LT(RunOnce(sim, {-0.5, 0, 0}, heading)[0], -kSlopeTravelM);
    EXPECT_GT(RunOnce(sim, {0, 0.5, 0}, heading)[1], kSlopeTravelM);
    EXPECT_LT(RunOnce(sim, {0, -0.5, 0}, heading)[1], -kSlopeTravelM);
    EXPECT_GT(RunOnce(sim, {0, 0, 0.5}, heading)[5], kMinTurnRad);
  }
}

TEST_F(SimulatorTest, ImuReadsTheSlope) {
  Simulator sim{SimConfig{}};
  const double slope = 18 * M_PI / 180;
  const double kTolRad = 2.5 * M_PI / 180;  // the standing torso sits within a few degrees of the plane
  ASSERT_EQ(sim.Place(0, 0, kUphill), RunOutcome::kCompleted);
  EXPECT_NEAR(sim.TruePitchRoll()[0], -slope, kTolRad);  // nose up
  ASSERT_EQ(sim.Place(0, 0, kDownhill), RunOutcome::kCompleted);
  EXPECT_NEAR(sim.TruePitchRoll()[0], slope, kTolRad);
  ASSERT_EQ(sim.Place(0, 0, kAcross), RunOutcome::kCompleted);  // left side downhill
  EXPECT_NEAR(sim.TruePitchRoll()[1], -slope, kTolRad);
  EXPECT_NEAR(sim.TruePitchRoll()[0], 0, kTolRad);
}

TEST_F(SimulatorTest, LowerFrictionSlipsFurtherDownhill) {
  SimConfig slippery;
  slippery.friction.sliding = 0.5;
  Simulator grippy{SimConfig{}}, slips(slippery);
  // Stepping on the spot facing across the slope: the body's left (+y) is downhill.
  const double grip_slip = RunOnce(grippy, Eigen::Vector3d::Zero(), kAcross)[1];
  const double low_slip = RunOnce(slips, Eigen::Vector3d::Zero(), kAcross)[1];
  EXPECT_GT(grip_slip, 0);
  EXPECT_GT(low_slip, grip_slip);
}

TEST_F(SimulatorTest, SameConfigSameTrajectory) {
  Simulator a{SimConfig{}}, b{SimConfig{}};
  EXPECT_EQ(RunOnce(a, {0.5, 0.5, 0.5}, 1.0), RunOnce(b, {0.5, 0.5, 0.5}, 1.0));
}

// Torso poses after every step of one command from a fresh placement (optionally standing
// `stand_s` first, which the latency test uses as the reference delay).
std::vector<Pose> StepPoses(Simulator& sim, const Eigen::Vector3d& command, double stand_s = 0) {
  EXPECT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  std::vector<Pose> poses;
  const auto record = [&](const Simulator& s) { poses.push_back(s.TorsoPose()); };
  if (stand_s > 0) {
    const int steps = static_cast<int>(std::lround(stand_s / sim.config().timestep_s));
    for (int i = 0; i < steps; ++i) {
      EXPECT_EQ(sim.Stand(sim.config().timestep_s), RunOutcome::kCompleted);
      record(sim);
    }
  }
  EXPECT_EQ(sim.RunCommand(command, record, 1), RunOutcome::kCompleted);
  return poses;
}

// With latency L the servos see each target L later: after a placement (constant targets, so no
// targets in flight) running a command equals standing for L and then running it without
// latency, step for step, and differs from running it at once.
TEST_F(SimulatorTest, LatencyDelaysServoTargets) {
  SimConfig delayed = Flat();
  delayed.actuators.latency_s = 0.05;
  Simulator lagging(delayed), prompt(Flat());
  const Eigen::Vector3d command(0.5, 0, 0.3);
  const std::vector<Pose> lag = StepPoses(lagging, command);
  const std::vector<Pose> reference = StepPoses(prompt, command, delayed.actuators.latency_s);
  const std::vector<Pose> at_once = StepPoses(prompt, command);
  ASSERT_EQ(lag.size(), at_once.size());
  const double kSameM = 1e-9;  // same state, same controls: identical up to rounding
  double max_diff = 0, max_diff_at_once = 0;
  for (size_t i = 0; i < lag.size(); ++i) {
    max_diff = std::max(max_diff, (lag[i].position_m - reference[i].position_m).norm());
    max_diff_at_once = std::max(max_diff_at_once, (lag[i].position_m - at_once[i].position_m).norm());
  }
  EXPECT_LT(max_diff, kSameM);
  const double kVisibleM = 0.01;  // 50 ms of a walking gait moves the torso by centimetres
  EXPECT_GT(max_diff_at_once, kVisibleM);
}

// The dead band is continuous with the plain servo: a backlash of 1e-9 rad (the dead-band path,
// ctrl rewritten before every step) walks the same path as backlash 0 (ctrl untouched) to within
// micrometres. Machine-independent, unlike a recorded pose.
TEST_F(SimulatorTest, VanishingBacklashIsThePlainServo) {
  SimConfig tiny = Flat();
  tiny.actuators.backlash_rad = 1e-9;
  Simulator a(tiny), plain(Flat());
  const Eigen::Vector3d command(0.5, 0.5, 0.5);
  ASSERT_EQ(a.Place(0, 0, 1.0), RunOutcome::kCompleted);
  ASSERT_EQ(plain.Place(0, 0, 1.0), RunOutcome::kCompleted);
  const Vec6 with = RunOnce(a, command), without = RunOnce(plain, command);
  EXPECT_LT((with - without).cwiseAbs().maxCoeff(), 1e-6) << (with - without).transpose();
}

// Backlash b is a dead band of +-b/2 around each servo target: the joints stop short of their
// targets under load, so the torso stands lower and walks a visibly different path; the same
// config still gives the same trajectory.
TEST_F(SimulatorTest, BacklashChangesTheMotionDeterministically) {
  SimConfig loose = Flat();
  loose.actuators.backlash_rad = 0.1;
  Simulator a(loose), b(loose), tight(Flat());
  const Eigen::Vector3d command(0.5, 0, 0.3);
  ASSERT_EQ(tight.Place(0, 0, 0), RunOutcome::kCompleted);
  const double tight_z = tight.TorsoPose().position_m.z();
  ASSERT_EQ(a.Place(0, 0, 0), RunOutcome::kCompleted);
  const double loose_z = a.TorsoPose().position_m.z();
  const Vec6 with = RunOnce(a, command), again = RunOnce(b, command), without = RunOnce(tight, command);
  EXPECT_EQ(with, again);
  const double kVisible = 0.005;  // m and rad: well above rounding, below the gait's own scale
  EXPECT_GT((with - without).cwiseAbs().maxCoeff(), kVisible) << (with - without).transpose();
  EXPECT_LT(loose_z, tight_z) << "the joints give way by up to b/2 under the robot's weight";
}

TEST_F(SimulatorTest, TippingOverIsReportedAsAFall) {
  SimConfig c;
  c.slope_deg = 30;
  c.payload.mass_kg = 60;  // a heavy block hung far out on the downhill side
  c.payload.position_body_m = Eigen::Vector3d(0, 0.8, 0.8);
  Simulator sim(c);
  RunOutcome outcome = sim.Place(0, 0, kAcross);
  if (outcome == RunOutcome::kCompleted) outcome = sim.RunCommand({0, 0.5, 0});
  EXPECT_EQ(outcome, RunOutcome::kFell);
}

std::string BuiltInXml() {
  std::ifstream in(std::string(DGMM_SOURCE_DIR) + "/datasets/robots/scorpion.xml");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) {
    s.replace(at, from.size(), to);
  }
  return s;
}

TEST_F(SimulatorTest, UserRobotWithOtherNamesWalks) {
  const auto dir = std::filesystem::temp_directory_path() / "dgmm_sim_user_robot";
  std::filesystem::create_directories(dir);
  std::string xml = Replace(BuiltInXml(), "\"leg", "\"foot");
  xml = Replace(xml, "name=\"torso\"", "name=\"chassis\"");
  xml = Replace(xml, "name=\"floor\"", "name=\"ground\"");
  std::ofstream(dir / "robot.xml") << xml;
  SimConfig c = Flat();
  c.mjcf_path = (dir / "robot.xml").string();
  c.names = {"chassis", "ground", "foot"};
  Simulator sim(c);
  EXPECT_GT(RunOnce(sim, {0.5, 0, 0})[0], kMinTravelM);
  std::filesystem::remove_all(dir);
}

// The battery's second robot (datasets/robots/harvestman.json: longer splayed legs, lighter
// torso) walks on the 18 degree slope in every heading without falling.
TEST_F(SimulatorTest, SecondRobotWalksOnTheSlope) {
  const SimConfig c = LoadSimConfig(std::string(DGMM_SOURCE_DIR) + "/datasets/robots/harvestman.json");
  Simulator sim(c);
  const double kDocumentedMassKg = 5.5 + 8 * (0.10 + 0.20 + 0.12);  // datasets/robots/harvestman.xml
  EXPECT_NEAR(sim.total_mass_kg(), kDocumentedMassKg, 1e-3);
  EXPECT_NEAR(sim.legs()[0].tibia_m, 0.19, 1e-3);
  const double kSlopeTravelM = 0.08;  // nominal 0.3 m at command 0.5 (stride 0.10 m)
  for (double heading : {kUphill, kAcross, kDownhill, -kAcross}) {
    SCOPED_TRACE(heading);
    EXPECT_GT(RunOnce(sim, {0.5, 0, 0}, heading)[0], kSlopeTravelM);
    EXPECT_LT(RunOnce(sim, {0, -0.5, 0}, heading)[1], -kSlopeTravelM);
    EXPECT_GT(RunOnce(sim, {0, 0, 0.5}, heading)[5], kMinTurnRad);
    // Five executions in a row, as the paper protocol does, without a fall.
    ASSERT_EQ(sim.Place(0, 0, heading), RunOutcome::kCompleted);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(sim.RunCommand({1, 0.5, -0.5}), RunOutcome::kCompleted);
  }
}

TEST_F(SimulatorTest, BrokenUserRobotsAreInputErrors) {
  const auto dir = std::filesystem::temp_directory_path() / "dgmm_sim_bad_robot";
  std::filesystem::create_directories(dir);
  const std::pair<std::string, std::string> cases[] = {
      {Replace(BuiltInXml(), "name=\"leg5_knee\" joint", "name=\"leg5_elbow\" joint"), "leg5_knee"},
      {Replace(BuiltInXml(), "<freejoint name=\"root\"/>", ""), "free joint"},
      {Replace(BuiltInXml(), "<joint name=\"leg2_hip_pitch\" class=\"hip_pitch\"/>",
               "<joint name=\"leg2_hip_pitch\" class=\"hip_pitch\" axis=\"0 1 0\"/>"),
       "axes"},
      {"<mujoco><worldbody><body", "MJCF"},
  };
  for (const auto& [xml, expected] : cases) {
    std::ofstream(dir / "robot.xml") << xml;
    SimConfig c;
    c.mjcf_path = (dir / "robot.xml").string();
    try {
      Simulator sim(c);
      ADD_FAILURE() << "accepted a robot without " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  SimConfig payload_without_body;
  payload_without_body.mjcf_path = (dir / "robot.xml").string();
  std::ofstream(dir / "robot.xml") << Replace(BuiltInXml(), "name=\"payload\"", "name=\"cargo\"");
  payload_without_body.payload.mass_kg = 1;
  EXPECT_THROW(Simulator{payload_without_body}, InputError);
  std::filesystem::remove_all(dir);
}

TEST_F(SimulatorTest, GeometrySnapshotHasThePlaneAndTheRobot) {
  Simulator sim{SimConfig{}};
  sim.Place(0, 0, 0);
  const auto geoms = sim.Geometry();
  int planes = 0, spheres = 0, boxes = 0;
  for (const auto& g : geoms) {
    planes += g.type == GeomSnapshot::Type::kPlane;
    spheres += g.type == GeomSnapshot::Type::kSphere;
    boxes += g.type == GeomSnapshot::Type::kBox;
  }
  EXPECT_EQ(planes, 1);
  EXPECT_EQ(spheres, 8);  // feet
  EXPECT_EQ(boxes, 1);    // torso (the payload is hidden when it has no mass)
}

}  // namespace
}  // namespace dgmm::sim
