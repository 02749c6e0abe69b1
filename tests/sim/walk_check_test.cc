#include "sim/walk_check.h"

#include <gtest/gtest.h>

#include "core/set_warnings.h"
#include "robot_files.h"
#include "sim/protocol.h"

namespace dgmm::sim {
namespace {

// A set of the protocol's layout: commands forward +0.5, turn -0.5 and one mixed, `per` samples
// each, every forward sample travelling `forward` m and every turn sample yawing `yaw` rad.
SampleSet Recorded(double forward, double yaw, int per = 3) {
  SampleSet s;
  s.command_dim_names = {"long", "lat", "turn"};
  s.commands.resize(3, 3);
  s.commands << 0.5, 0, 0, 0, 0, -0.5, 0.5, 0.5, 0;
  s.command_labels = {"+0.5,0,0", "0,0,-0.5", "+0.5,+0.5,0"};
  s.command.resize(3 * per);
  s.x = Eigen::MatrixXd::Zero(3 * per, 6);
  for (int i = 0; i < 3 * per; ++i) {
    s.command(i) = i / per;
    if (i / per == 0) s.x(i, 0) = forward;
    if (i / per == 1) s.x(i, 5) = yaw;
    if (i / per == 2) s.x(i, 0) = s.x(i, 1) = -1;  // mixed: never judged
  }
  return s;
}

// stride 0.1 m and turn 0.4 rad per cycle, 2 cycles: +0.5 forward commands 0.1 m, -0.5 turn -0.4 rad.
constexpr CommandedWalk kWant{0.1, 0.4, 2};

TEST(WalkCheck, APureCommandIsMeasuredAgainstStrideOrTurnTimesCycles) {
  const std::vector<WalkRatio> r = WalkRatios(Recorded(0.09, -0.2), kWant);
  ASSERT_EQ(r.size(), 2u);  // the mixed command is not judged
  EXPECT_EQ(r[0].command, "long +0.5");
  EXPECT_NEAR(r[0].ratio, 0.9, 1e-12);
  EXPECT_NEAR(r[0].commanded, 0.1, 1e-12);
  EXPECT_EQ(r[1].command, "turn -0.5");
  EXPECT_NEAR(r[1].ratio, 0.5, 1e-12);
}

TEST(WalkCheck, OnlyCommandsFarFromWhatTheGaitCommandsAreWarnedOf) {
  EXPECT_EQ(WalkWarning(WalkRatios(Recorded(0.09, -0.36), kWant)), "");
  const std::string slow = WalkWarning(WalkRatios(Recorded(0.02, -0.36), kWant));
  EXPECT_NE(slow.find("long +0.5 moved it 0.2 of the commanded 0.1 m"), std::string::npos) << slow;
  EXPECT_EQ(slow.find("turn"), slow.find("turn x cycles")) << slow;  // the turn walked
  // The wrong way and too far are off too, the farthest from 1 named first.
  const std::string both = WalkWarning(WalkRatios(Recorded(0.2, 0.1), kWant));
  EXPECT_LT(both.find("turn -0.5 moved it -0.25"), both.find("long +0.5 moved it 2 ")) << both;
}

TEST(WalkCheck, NothingIsJudgedWithoutTheGaitsCommand) {
  EXPECT_TRUE(WalkRatios(Recorded(0.0, 0.0), CommandedWalk{}).empty());  // a replay, or no robot block
  EXPECT_EQ(CommandedWalkOf(SimConfig{}, 0.4).cycles, 0);                  // the built-in robot
  SampleSet other = Recorded(0.0, 0.0);
  other.command_dim_names = {"a", "b", "c"};
  EXPECT_TRUE(WalkRatios(other, kWant).empty());
}

// 3 mm of tracker noise is 3% of the 0.1 m a half command moves this robot: no warning; on a robot
// that moves 0.04 m, 7.5%: named with both lengths. Nothing is commanded by a replay.
TEST(WalkCheck, ATrackerCoarseForTheRobotsStepsIsWarnedOf) {
  EXPECT_EQ(TrackerNoiseWarning(0.003, kWant), "");
  const std::string w = TrackerNoiseWarning(0.003, CommandedWalk{0.04, 0.4, 2});
  EXPECT_NE(w.find("noise.tracker_position_sd_m: 0.003 m is 7.5% of the 0.04 m a half command moves the robot"),
            std::string::npos) << w;
  EXPECT_EQ(TrackerNoiseWarning(0.003, CommandedWalk{}), "");
}

// The hexapod walks in its tripod and its recording says nothing of it; in a wave of a 0.2 s cycle
// (a swing of 33 ms) it does not (forward 0.08 of the command, turns the wrong way), and the set
// keeps the warning for the analyses that read it.
TEST(WalkCheck, TheProtocolWarnsWhenTheGaitDoesNotWalkTheRobot) {
  ProtocolOptions o;
  o.seed = 3;
  o.placements = 78;  // every command at three headings (26 placements draw only some)
  o.executions_per_placement = 1;
  SimConfig c = LoadSimConfig((test::kRobots / "hexapod.json").string());
  SimSummary walks, short_of;
  SimulateProtocol(c, o, {}, &walks);
  for (const std::string& w : walks.warnings) EXPECT_EQ(w.find("does not walk"), std::string::npos) << w;
  c.robot->gait.pattern = "wave";
  c.robot->gait.period_s = 0.2;
  const SampleSet set = SimulateProtocol(c, o, {}, &short_of);
  bool warned = false;
  for (const std::string& w : KeptWarnings(set)) warned |= w.find("does not walk the robot as it commands") != std::string::npos;
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace dgmm::sim
