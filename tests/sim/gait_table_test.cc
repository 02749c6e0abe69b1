// Timing of the generic gait (lib/sim/gait_table.h).
#include "sim/gait_table.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace dgmm::sim {
namespace {

// Six legs in the order front-left, middle-left, rear-left, front-right, middle-right, rear-right.
std::vector<LegPlace> Hexapod() {
  return {{1, 0.1}, {1, 0}, {1, -0.1}, {-1, 0.1}, {-1, 0}, {-1, -0.1}};
}

TEST(GaitTable, TripodAlternatesAlongEachSideAndAcross) {
  GaitDescription g;
  g.pattern = "tripod";
  const GaitTiming t = ResolveGait(g, Hexapod(), "test");
  EXPECT_EQ(t.phase, (std::vector<double>{0, 0.5, 0, 0.5, 0, 0.5}));
  EXPECT_EQ(t.phase_backward, t.phase);  // symmetric in time: the same backwards, bit for bit
  EXPECT_DOUBLE_EQ(t.duty, 0.5);
}

// Within one cycle starting at `from`, the order in which the legs `which` start their swing
// (a leg lifts at u = duty, i.e. at time phase + duty).
std::vector<int> SwingOrder(const std::vector<double>& phase, double duty, const std::vector<int>& which) {
  std::vector<int> order = which;
  auto lift = [&](int i) { double v = phase[i] + duty; return v - std::floor(v); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lift(a) < lift(b); });
  while (order.front() != which.back()) std::rotate(order.begin(), order.begin() + 1, order.end());
  return order;
}

TEST(GaitTable, TetrapodAndWaveSwingBackToFrontAndReverseForBackwardCommands) {
  for (const char* pattern : {"tetrapod", "wave"}) {
    GaitDescription g;
    g.pattern = pattern;
    const GaitTiming t = ResolveGait(g, Hexapod(), "test");
    // Left legs 0 (front), 1, 2 (rear); right legs 3 (front), 4, 5 (rear): forwards rear first.
    EXPECT_EQ(SwingOrder(t.phase, t.duty, {0, 1, 2}), (std::vector<int>{2, 1, 0})) << pattern;
    EXPECT_EQ(SwingOrder(t.phase, t.duty, {3, 4, 5}), (std::vector<int>{5, 4, 3})) << pattern;
    // Backwards the front legs trail: they swing first.
    EXPECT_EQ(SwingOrder(t.phase_backward, t.duty, {2, 1, 0}), (std::vector<int>{0, 1, 2})) << pattern;
    EXPECT_EQ(SwingOrder(t.phase_backward, t.duty, {5, 4, 3}), (std::vector<int>{3, 4, 5})) << pattern;
  }
  GaitDescription custom;
  custom.pattern = "custom";
  custom.phases = {0, 0.1, 0.2, 0.3, 0.4, 0.5};
  EXPECT_EQ(ResolveGait(custom, Hexapod(), "test").phase_backward, custom.phases);  // as given
}

TEST(GaitTable, LegsAreOrderedByPositionNotByListOrder) {
  std::vector<LegPlace> shuffled = {{-1, -0.1}, {1, 0}, {-1, 0.1}, {1, 0.1}, {-1, 0}, {1, -0.1}};
  GaitDescription g;
  g.pattern = "wave";
  const GaitTiming t = ResolveGait(g, shuffled, "test");
  // Wave: rear left first, then middle and front left, then the right side back to front.
  EXPECT_NEAR(t.phase[5], 0.0, 1e-12);
  EXPECT_NEAR(t.phase[1], 1.0 / 6, 1e-12);
  EXPECT_NEAR(t.phase[3], 2.0 / 6, 1e-12);
  EXPECT_NEAR(t.phase[0], 3.0 / 6, 1e-12);
  EXPECT_NEAR(t.phase[2], 5.0 / 6, 1e-12);
}

// The wave swings one side and then the other: a sideways command starts with the trailing side.
TEST(GaitTable, AWaveStartsASidewaysStepWithItsTrailingSide) {
  const std::vector<int> sides = {1, 1, 1, -1, -1, -1};
  GaitDescription g;
  g.pattern = "wave";
  const GaitTiming t = ResolveGait(g, Hexapod(), "test");
  EXPECT_TRUE(t.side_sequential);
  for (const auto* phase : {&t.phase, &t.phase_backward}) {
    for (double lateral : {0.5, -0.5}) {
      const double shift = LateralShift(t, *phase, sides, lateral);
      // The first leg to lift after the start, with the shift, is on the trailing side.
      int first = -1;
      double earliest = 2;
      for (int i = 0; i < 6; ++i) {
        double lift = (*phase)[i] + shift + t.duty;
        lift -= std::floor(lift);
        if (lift < earliest) earliest = lift, first = i;
      }
      EXPECT_EQ(sides[first], lateral > 0 ? -1 : 1) << "lateral " << lateral;
    }
    EXPECT_EQ(LateralShift(t, *phase, sides, 0.0), 0.0);  // no sideways part
  }
  g.pattern = "tripod";
  const GaitTiming tripod = ResolveGait(g, Hexapod(), "test");
  EXPECT_EQ(LateralShift(tripod, tripod.phase, sides, 0.5), 0.0);  // sides alternate: unchanged
  EXPECT_EQ(LateralShift(tripod, tripod.phase, sides, -0.5), 0.0);
}

TEST(GaitTable, TrotPairsDiagonalsAndAutoPicksByLegCount) {
  const std::vector<LegPlace> quad = {{1, 0.2}, {-1, 0.2}, {1, -0.2}, {-1, -0.2}};
  const GaitTiming t = ResolveGait(GaitDescription{}, quad, "test");  // auto: trot
  EXPECT_EQ(t.phase[0], t.phase[3]);
  EXPECT_EQ(t.phase[1], t.phase[2]);
  EXPECT_NE(t.phase[0], t.phase[1]);
}

TEST(GaitTable, APatternForAnotherLegCountIsRefusedNamingIt) {
  GaitDescription g;
  g.pattern = "trot";
  try {
    ResolveGait(g, Hexapod(), "robot.json");
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("robot.gait.pattern"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("needs 4 legs"), std::string::npos) << e.what();
  }
  g.pattern = "custom";
  g.phases = {0, 0.5};
  EXPECT_THROW(ResolveGait(g, Hexapod(), "robot.json"), std::exception);
  g.pattern = "auto";
  g.phases.clear();
  EXPECT_THROW(ResolveGait(g, {{1, 0}, {-1, 0}, {1, 0.1}}, "robot.json"), std::exception);  // three legs
  g.pattern = "alternating";
  try {
    ResolveGait(g, {{1, 0}, {-1, 0}, {1, 0.1}, {-1, 0.1}, {1, 0.2}}, "robot.json");
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("3 left and 2 right"), std::string::npos) << e.what();
  }
}

// A hexapod that lost its rear right leg: the wave on five legs, one foot in the air at a time.
TEST(GaitTable, TheWaveTakesAnyNumberOfLegsOneFootInTheAirAtATime) {
  std::vector<LegPlace> five = Hexapod();
  five.pop_back();
  GaitDescription g;  // auto: the sides differ, so the wave
  const GaitTiming t = ResolveGait(g, five, "test");
  EXPECT_TRUE(t.side_sequential);
  EXPECT_DOUBLE_EQ(t.duty, 0.8);
  // Left rear (2), middle (1), front (0), then right middle (4), front (3).
  EXPECT_EQ(SwingOrder(t.phase, t.duty, {2, 1, 0, 4, 3}), (std::vector<int>{3, 2, 1, 0, 4}));
  for (int i = 0; i < 100; ++i) {  // swings never overlap: at most one foot in the air
    const double u = 0.005 + 0.01 * i;  // between the swings' ends at multiples of 0.2
    int up = 0;
    for (double p : t.phase) up += (u - p - std::floor(u - p)) >= t.duty;
    EXPECT_LE(up, 1) << "at " << u;
  }
  g.pattern = "wave";  // on six legs, the table it has always had
  EXPECT_EQ(ResolveGait(g, Hexapod(), "test").phase,
            (std::vector<double>{2.0 / 6, 1.0 / 6, 0.0, 5.0 / 6, 4.0 / 6, 3.0 / 6}));
  EXPECT_EQ(ResolveGait(g, Hexapod(), "test").duty, 5.0 / 6);
}

// Ten legs, five a side: auto alternates neighbours along a side and across; on 4, 6 and 8 legs
// the alternating pattern is the trot, the tripod and the alternating tetrapod.
TEST(GaitTable, TheAlternatingPatternTakesAnyEqualNumberOfLegsASide) {
  std::vector<LegPlace> ten;
  for (int k = 0; k < 5; ++k) ten.push_back({1, 0.1 * k}), ten.push_back({-1, 0.1 * k});
  const GaitTiming t = ResolveGait(GaitDescription{}, ten, "test");
  EXPECT_DOUBLE_EQ(t.duty, 0.5);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NE(t.phase[2 * k], t.phase[2 * k + 1]) << "across, pair " << k;
    if (k > 0) EXPECT_NE(t.phase[2 * k], t.phase[2 * k - 2]) << "along the left side, leg " << k;
  }
  for (const auto& [pattern, legs] : {std::pair<std::string, std::vector<LegPlace>>{"tripod", Hexapod()},
                                      {"trot", {{1, 0.2}, {-1, 0.2}, {1, -0.2}, {-1, -0.2}}},
                                      {"alternating_tetrapod", {{1, 3}, {1, 2}, {1, 1}, {1, 0}, {-1, 3}, {-1, 2},
                                                                {-1, 1}, {-1, 0}}}}) {
    GaitDescription named, alternating;
    named.pattern = pattern;
    alternating.pattern = "alternating";
    EXPECT_EQ(ResolveGait(alternating, legs, "test").phase, ResolveGait(named, legs, "test").phase) << pattern;
  }
}

TEST(GaitTable, FootOffsetIsContinuousAndOnTheGroundInStance) {
  const Eigen::Vector2d d(0.04, -0.01);
  const double duty = 0.6, lift = 0.03;
  EXPECT_TRUE(FootOffset(0.0, duty, d, lift).isApprox(Eigen::Vector3d(0.02, -0.005, 0)));
  EXPECT_TRUE(FootOffset(duty - 1e-9, duty, d, lift).isApprox(Eigen::Vector3d(-0.02, 0.005, 0), 1e-6));
  EXPECT_TRUE(FootOffset(1 - 1e-9, duty, d, lift).isApprox(FootOffset(0.0, duty, d, lift), 1e-6));
  for (double u = 0; u < duty; u += 0.05) EXPECT_EQ(FootOffset(u, duty, d, lift).z(), 0) << u;
  EXPECT_NEAR(FootOffset(0.8, duty, d, lift).z(), lift, 1e-12);  // the middle of the swing
  EXPECT_TRUE(FootOffset(-0.3, duty, d, lift).isApprox(FootOffset(0.7, duty, d, lift)));
}

// The crawl's sway: each leg's target lies a share of the way towards the other three feet's
// centroid (for a rectangle, share / 3 of the way to the opposite corner; none where the other
// feet leave the centre a wide margin), and the swing weights
// of its back-to-back swings add up to 1, so the torso blends from one target to the next.
TEST(GaitTable, ACrawlSwaysAwayFromEachSwingingFootAndBlendsBetweenSwings) {
  EXPECT_DOUBLE_EQ(ResolveSway(-1, 0.75), 0.1);  // default: a statically stable duty factor
  EXPECT_DOUBLE_EQ(ResolveSway(-1, 0.5), 0.0);   // the trot does not sway
  EXPECT_DOUBLE_EQ(ResolveSway(0.3, 0.5), 0.3);  // as given
  const std::vector<Eigen::Vector2d> feet = {{0.3, 0.2}, {-0.3, 0.2}, {0.3, -0.2}, {-0.3, -0.2}};
  const std::vector<Eigen::Vector2d> to = SwayTargets(feet, 0.6);
  for (std::size_t i = 0; i < feet.size(); ++i) EXPECT_TRUE(to[i].isApprox(-0.2 * feet[i])) << i;
  // Six feet as long as wide: lifting any one leaves the centre well inside the other five.
  const std::vector<Eigen::Vector2d> six = {{0.3, 0.2}, {0, 0.25}, {-0.3, 0.2}, {0.3, -0.2}, {0, -0.25}, {-0.3, -0.2}};
  for (const Eigen::Vector2d& target : SwayTargets(six, 0.6)) EXPECT_EQ(target, Eigen::Vector2d::Zero());
  // Six feet in a short row (fore-aft 0.1 of the width): lifting a corner foot needs some sway.
  const std::vector<Eigen::Vector2d> row = {{0.02, 0.2}, {0, 0.2}, {-0.02, 0.2}, {0.02, -0.2}, {0, -0.2}, {-0.02, -0.2}};
  const Eigen::Vector2d corner = SwayTargets(row, 0.6)[0];
  EXPECT_GT(corner.norm(), 0.0);
  EXPECT_LT(corner.norm(), 0.6 * row[0].norm() / 5 + 1e-12);
  GaitDescription g;
  g.pattern = "crawl";
  const GaitTiming t = ResolveGait(g, {{1, 0.3}, {1, -0.3}, {-1, 0.3}, {-1, -0.3}}, "test");
  for (double time = 0; time < 1; time += 0.01) {
    double sum = 0, swinging = 0;
    for (std::size_t i = 0; i < 4; ++i) {
      const double u = time - t.phase[i];
      sum += SwingWeight(u, t.duty);
      if (u - std::floor(u) >= t.duty) swinging += SwingWeight(u, t.duty);
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << time;
    EXPECT_GE(swinging, 0.5 - 1e-12) << time;  // the leg in the air weighs at least half
  }
  EXPECT_DOUBLE_EQ(SwingWeight(0.875, 0.75), 1.0);  // mid-swing
  EXPECT_DOUBLE_EQ(SwingWeight(0.375, 0.75), 0.0);  // mid-stance
}

}  // namespace
}  // namespace dgmm::sim
