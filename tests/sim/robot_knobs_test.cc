// Knobs of a robot described by a robot block (lib/sim/robot_knobs.cc via knobs.h).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <filesystem>

#include "sim/knobs.h"
#include "sim/mujoco_model.h"
#include "sim/simulator.h"

namespace dgmm::sim {
namespace {

SimConfig Hexapod() {
  return LoadSimConfig((std::filesystem::path(DGMM_SOURCE_DIR) / "datasets/robots/hexapod.json").string());
}

int IndexOf(const std::vector<Knob>& knobs, const std::string& name) {
  const auto it = std::find_if(knobs.begin(), knobs.end(), [&](const Knob& k) { return k.name == name; });
  return it == knobs.end() ? -1 : static_cast<int>(it - knobs.begin());
}

TEST(RobotKnobs, PerLegKnobsAreNamedByLegNameAndSidesByTheSideRule) {
  const SimConfig c = Hexapod();
  const auto knobs = EnumerateKnobs(c);
  const int leg = IndexOf(knobs, "actuators.middle_right.gain");
  ASSERT_GE(leg, 0);
  EXPECT_EQ(knobs[leg].leg, "middle_right");
  const int left = IndexOf(knobs, "actuators.left_side.gain");
  ASSERT_GE(left, 0);
  EXPECT_EQ(knobs[left].members, (std::vector<std::string>{"front_left", "middle_left", "rear_left"}));
  EXPECT_LT(IndexOf(knobs, "actuators.leg0.gain"), 0) << "no built-in leg names";
}

TEST(RobotKnobs, LatencyAndBacklashChangeTheWalkAndATorqueReplayHasNoBacklash) {
  const SimConfig c = Hexapod();
  const auto knobs = EnumerateKnobs(c);
  const int latency = IndexOf(knobs, "actuators.latency_s");
  const int backlash = IndexOf(knobs, "actuators.backlash_rad");
  ASSERT_GE(latency, 0);
  ASSERT_GE(backlash, 0);
  EXPECT_NEAR(knobs[latency].probes.at(0), 0.07 * c.robot->gait.period_s, 1e-12) << "relative to the gait cycle";
  ProtocolOptions options;
  options.seed = 4;
  options.placements = 1;
  const SampleSet nominal = SimulateWithKnobs(c, options, knobs, {});
  for (const auto& [knob, value] : {std::pair{latency, 0.06}, std::pair{backlash, 0.1}}) {
    const SampleSet changed = SimulateWithKnobs(c, options, knobs, {{knob, value}});
    ASSERT_EQ(changed.x.rows(), nominal.x.rows()) << knobs[knob].name;
    EXPECT_GT((changed.x - nominal.x).norm(), 1e-3 * nominal.x.norm()) << knobs[knob].name;
  }
}

TEST(RobotKnobs, PayloadAndOffsetsScaleWithTheModel) {
  const SimConfig c = Hexapod();
  const auto knobs = EnumerateKnobs(c);
  const double mass = Simulator(c).total_mass_kg();
  const double reach = Simulator(c).leg_reach_m();
  const Knob& payload = knobs[IndexOf(knobs, "payload.mass_kg")];
  EXPECT_NEAR(payload.probes.at(0), 0.15 * mass, 1e-9);
  const Knob& x = knobs[IndexOf(knobs, "payload.position_x_m")];
  EXPECT_NEAR(x.hi, 0.6 * reach, 1e-9);
}

TEST(RobotKnobs, ValuesApplyToTheConfigOrToTheModelsOwnValues) {
  const SimConfig c = Hexapod();
  const auto knobs = EnumerateKnobs(c);
  ModelEdit edit;
  const SimConfig leg = ApplyKnobs(c, knobs, {{IndexOf(knobs, "actuators.middle_right.gain"), 0.4}}, &edit);
  EXPECT_EQ(leg.robot->leg_gain.at("middle_right"), 0.4);
  EXPECT_FALSE(edit);
  const SimConfig side = ApplyKnobs(c, knobs, {{IndexOf(knobs, "actuators.right_side.gain"), 0.5}}, &edit);
  EXPECT_EQ(side.robot->leg_gain.size(), 3u);
  ApplyKnobs(c, knobs, {{IndexOf(knobs, "geoms.friction_scale"), 0.5}, {IndexOf(knobs, "payload.mass_kg"), 0.3}},
             &edit);
  ASSERT_TRUE(edit);
  MjModelPtr original = LoadRobotModel(c);
  MjModelPtr edited = LoadRobotModel(c);
  edit(edited.get());
  for (int g = 0; g < original->ngeom; ++g) {
    EXPECT_DOUBLE_EQ(edited->geom_friction[3 * g], 0.5 * original->geom_friction[3 * g]);
  }
  const SimConfig loaded = ApplyKnobs(c, knobs, {{IndexOf(knobs, "payload.mass_kg"), 0.3}}, &edit);
  EXPECT_EQ(loaded.payload.mass_kg, 0.3);
  EXPECT_NEAR(Simulator(loaded).total_mass_kg(), Simulator(c).total_mass_kg() + 0.3, 1e-9);
}

TEST(RobotKnobs, AKnobChangesWhatTheRobotDoes) {
  const SimConfig c = Hexapod();
  const auto knobs = EnumerateKnobs(c);
  ProtocolOptions options;
  options.protocol = Protocol::kPaper;
  options.seed = 4;
  options.placements = 1;
  const SampleSet nominal = SimulateWithKnobs(c, options, knobs, {});
  const SampleSet weak = SimulateWithKnobs(c, options, knobs, {{IndexOf(knobs, "actuators.front_left.gain"), 0.2}});
  ASSERT_EQ(nominal.x.rows(), weak.x.rows());
  EXPECT_EQ(nominal.x, SimulateWithKnobs(c, options, knobs, {}).x);
  EXPECT_NE(nominal.x, weak.x);
}

}  // namespace
}  // namespace dgmm::sim
