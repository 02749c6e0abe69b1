// The wiring of lib/sim2real's simulator interface to lib/sim (app/wiring/mujoco_knob_simulator.h).
#include "app/wiring/mujoco_knob_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace dgmm::app {
namespace {

TEST(MujocoKnobSimulator, KnobsOfTheBuiltInRobotCarryLegSideAndPhysicalLimits) {
  const MujocoKnobSimulator sim{sim::SimConfig{}};
  const auto& knobs = sim.knobs();
  ASSERT_FALSE(knobs.empty());
  auto find = [&](const std::string& name) {
    return std::find_if(knobs.begin(), knobs.end(), [&](const sim2real::Knob& k) { return k.name == name; });
  };
  const auto leg3 = find("actuators.leg3.gain");
  ASSERT_NE(leg3, knobs.end());
  EXPECT_EQ(leg3->leg, "leg3");
  EXPECT_EQ(leg3->physical_min, 0);
  const auto left = find("actuators.left_side.gain");
  ASSERT_NE(left, knobs.end());
  EXPECT_EQ(left->side, "left");
  const auto px = find("payload.position_x_m");
  ASSERT_NE(px, knobs.end());
  EXPECT_EQ(px->role, sim2real::Knob::Role::kPayloadX);
  EXPECT_LT(px->physical_min, px->lo);
  for (const auto& k : knobs) {
    EXPECT_LE(k.lo, k.nominal) << k.name;
    EXPECT_GE(k.hi, k.nominal) << k.name;
  }
  EXPECT_GT(sim.total_mass_kg(), 5);
  EXPECT_GT(sim.leg_reach_m(), 0.1);
}

TEST(MujocoKnobSimulator, FingerprintFollowsTheConfigNotItsPath) {
  sim::SimConfig a;
  sim::SimConfig b = a;
  b.friction.sliding = 0.7;
  EXPECT_EQ(MujocoKnobSimulator(a).Fingerprint(), MujocoKnobSimulator(a).Fingerprint());
  EXPECT_NE(MujocoKnobSimulator(a).Fingerprint(), MujocoKnobSimulator(b).Fingerprint());
}

TEST(MujocoKnobSimulator, RecordingsAtTheSameKnobsArePairedAndKnobsChangeThem) {
  const MujocoKnobSimulator sim{sim::SimConfig{}};
  const sim2real::Recording rec{"paper", 3, 2};
  const SampleSet a = sim.Record(rec, {}, 1);
  const SampleSet b = sim.Record(rec, {}, 1);
  ASSERT_GT(a.size(), 0);
  EXPECT_EQ(a.x, b.x);
  int friction = -1;
  for (int k = 0; k < static_cast<int>(sim.knobs().size()); ++k) {
    if (sim.knobs()[k].name == "floor.friction.sliding") friction = k;
  }
  ASSERT_GE(friction, 0);
  const SampleSet c = sim.Record(rec, {{friction, 0.3}}, 1);
  ASSERT_EQ(c.x.rows(), a.x.rows());
  EXPECT_NE(c.x, a.x);
  EXPECT_NE(sim.ConfigJson({{friction, 0.3}}).find("0.3"), std::string::npos);
}

}  // namespace
}  // namespace dgmm::app
