// Knobs enumerated from the model, and applying them moves the simulated robot as physics says.
#include "sim/knobs.h"

#include <gtest/gtest.h>

#include <set>

#include "sim/simulator.h"

namespace dgmm::sim {
namespace {

TEST(Knobs, BuiltInRobotHasEveryFamilyAndBothSides) {
  const std::vector<Knob> knobs = EnumerateKnobs(SimConfig{});
  std::set<std::string> families, names;
  int legs = 0, sides = 0;
  for (const auto& k : knobs) {
    families.insert(k.family);
    names.insert(k.name);
    legs += k.kind == KnobKind::kLegGain;
    sides += k.kind == KnobKind::kSideGain;
    EXPECT_LE(k.lo, k.nominal) << k.name;
    EXPECT_GE(k.hi, k.nominal) << k.name;
    for (double p : k.probes) {
      EXPECT_GE(p, k.lo) << k.name;
      EXPECT_LE(p, k.hi) << k.name;
      EXPECT_NE(p, k.nominal) << k.name;
    }
  }
  EXPECT_EQ(legs, kNumLegs);
  EXPECT_EQ(sides, 2);
  for (const char* f : {"friction", "contact", "mass", "payload", "actuator_gain", "joint_damping", "latency"}) {
    EXPECT_TRUE(families.count(f)) << f;
  }
  EXPECT_TRUE(names.count("floor.solref.timeconst"));
}

TEST(Knobs, ConfigKnobsChangeTheConfigModelKnobsMakeAnEdit) {
  const SimConfig base;
  const std::vector<Knob> knobs = EnumerateKnobs(base);
  auto find = [&](const std::string& name) {
    for (size_t k = 0; k < knobs.size(); ++k) {
      if (knobs[k].name == name) return static_cast<int>(k);
    }
    return -1;
  };
  ModelEdit edit;
  SimConfig c = ApplyKnobs(base, knobs, {{find("floor.friction.sliding"), 0.5}}, &edit);
  EXPECT_DOUBLE_EQ(c.friction.sliding, 0.5);
  EXPECT_FALSE(static_cast<bool>(edit));
  c = ApplyKnobs(base, knobs, {{find("floor.solref.timeconst"), 0.06}}, &edit);
  EXPECT_TRUE(static_cast<bool>(edit));
  c = ApplyKnobs(base, knobs, {{find("actuators.left_side.gain"), 0.5}}, &edit);
  int halved = 0;
  for (double g : c.actuators.leg_gain) halved += g == 0.5;
  EXPECT_EQ(halved, kNumLegs / 2);  // the built-in robot: four legs per side
}

// On an 18 degree slope (tan = 0.32), a friction coefficient of 0.25 cannot hold the robot: it
// slides downhill (-x in the slope frame) far more than with the nominal friction.
TEST(Knobs, LowFrictionMovesTheRobotDownhill) {
  SimConfig base;
  const std::vector<Knob> knobs = EnumerateKnobs(base);
  int friction = -1;
  for (size_t k = 0; k < knobs.size(); ++k) {
    if (knobs[k].kind == KnobKind::kFrictionSliding) friction = static_cast<int>(k);
  }
  ASSERT_GE(friction, 0);
  auto downhill = [&](double mu) {
    ModelEdit edit;
    const SimConfig c = ApplyKnobs(base, knobs, {{friction, mu}}, &edit);
    Simulator sim(c, edit);
    sim.Place(0, 0, 0);
    const double x0 = sim.TorsoPose().position_m.x();
    sim.RunCommand(Eigen::Vector3d(0, 0, 0.5));
    return x0 - sim.TorsoPose().position_m.x();
  };
  const double nominal = downhill(1.0), slippery = downhill(0.25);
  EXPECT_GT(slippery, nominal + 0.02);
}

}  // namespace
}  // namespace dgmm::sim
