// Knobs enumerated from the model, and applying them moves the simulated robot as physics says.
#include "sim/knobs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <mujoco/mujoco.h>
#include <unistd.h>

#include "sim/mujoco_model.h"
#include "sim/protocol.h"
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
  for (const char* f : {"friction", "contact", "mass", "payload", "actuator_gain", "joint_damping", "latency",
                        "backlash", "tracker_noise"}) {
    EXPECT_TRUE(families.count(f)) << f;
  }
  for (const char* n : {"floor.solref.timeconst", "floor.solimp.dmax", "floor.solimp.width", "actuators.backlash_rad"}) {
    EXPECT_TRUE(names.count(n)) << n;
  }
  EXPECT_EQ(knobs.back().kind, KnobKind::kTrackerNoiseScale);  // appended last
}

// Torsional friction acts only in contacts of condim >= 4: the built-in robot's condim-3 contacts
// never use it, so it is no knob; the same robot with condim-4 feet has it.
TEST(Knobs, TorsionalFrictionIsAKnobOnlyWhereAContactUsesIt) {
  auto has_torsional = [](const SimConfig& c) {
    for (const Knob& k : EnumerateKnobs(c)) {
      if (k.kind == KnobKind::kFrictionTorsional) return true;
    }
    return false;
  };
  EXPECT_FALSE(has_torsional(SimConfig{}));
  std::ifstream in(std::string(DGMM_SOURCE_DIR) + "/datasets/robots/scorpion.xml");
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string three = "condim=\"3\"";
  for (size_t at = xml.find(three); at != std::string::npos; at = xml.find(three, at)) xml.replace(at, three.size(), "condim=\"4\"");
  const auto path = std::filesystem::temp_directory_path() / ("dgmm_condim4_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig c;
  c.mjcf_path = path.string();
  EXPECT_TRUE(has_torsional(c));
  std::filesystem::remove(path);
}

// The solimp knobs start from the compiled model (MuJoCo's default 0.9 0.95 0.001 0.5 2 for the
// built-in robot's floor); the tracker noise knob exists only when the tracker is noisy.
TEST(Knobs, NominalsComeFromTheModelAndTheConfig) {
  SimConfig base;
  base.actuators.backlash_rad = 0.05;
  std::vector<Knob> knobs = EnumerateKnobs(base);
  auto knob = [&](KnobKind kind) {
    for (const auto& k : knobs) {
      if (k.kind == kind) return k;
    }
    ADD_FAILURE() << "no knob of kind " << static_cast<int>(kind);
    return Knob{};
  };
  EXPECT_DOUBLE_EQ(knob(KnobKind::kFloorSolimpDmax).nominal, 0.95);
  EXPECT_EQ(knob(KnobKind::kFloorSolimpDmax).probes, std::vector<double>{0.7});
  EXPECT_DOUBLE_EQ(knob(KnobKind::kFloorSolimpWidth).nominal, 0.001);
  EXPECT_EQ(knob(KnobKind::kFloorSolimpWidth).probes, std::vector<double>{0.01});
  EXPECT_DOUBLE_EQ(knob(KnobKind::kBacklash).nominal, 0.05);
  EXPECT_DOUBLE_EQ(knob(KnobKind::kBacklash).probes.at(0), 0.08);
  base.noise.tracker_position_sd_m = base.noise.tracker_yaw_sd_rad = 0;
  base.noise.tracker_roll_sd_rad = base.noise.tracker_pitch_sd_rad = 0;
  knobs = EnumerateKnobs(base);
  for (const auto& k : knobs) EXPECT_NE(k.kind, KnobKind::kTrackerNoiseScale);
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
  c = ApplyKnobs(base, knobs, {{find("floor.solimp.dmax"), 0.7}, {find("floor.solimp.width"), 0.01}}, &edit);
  ASSERT_TRUE(static_cast<bool>(edit));
  {
    MjModelPtr model = LoadRobotModel(c);
    edit(model.get());
    const int g = mj_name2id(model.get(), mjOBJ_GEOM, "floor");
    ASSERT_GE(g, 0);
    EXPECT_DOUBLE_EQ(model->geom_solimp[mjNIMP * g + 0], 0.7);  // dmin 0.9 lowered to dmax
    EXPECT_DOUBLE_EQ(model->geom_solimp[mjNIMP * g + 1], 0.7);
    EXPECT_DOUBLE_EQ(model->geom_solimp[mjNIMP * g + 2], 0.01);
  }
  c = ApplyKnobs(base, knobs, {{find("actuators.backlash_rad"), 0.04}, {find("tracker.noise_scale"), 2.0}}, &edit);
  EXPECT_FALSE(static_cast<bool>(edit));
  EXPECT_DOUBLE_EQ(c.actuators.backlash_rad, 0.04);
  EXPECT_DOUBLE_EQ(c.noise.tracker_position_sd_m, 2 * base.noise.tracker_position_sd_m);
  EXPECT_DOUBLE_EQ(c.noise.tracker_yaw_sd_rad, 2 * base.noise.tracker_yaw_sd_rad);
  EXPECT_DOUBLE_EQ(c.noise.tracker_roll_sd_rad, 2 * base.noise.tracker_roll_sd_rad);
  EXPECT_DOUBLE_EQ(c.noise.tracker_pitch_sd_rad, 2 * base.noise.tracker_pitch_sd_rad);
  EXPECT_DOUBLE_EQ(c.noise.imu_pitch_sd_rad, base.noise.imu_pitch_sd_rad);  // the IMU's untouched
  EXPECT_DOUBLE_EQ(c.noise.imu_roll_sd_rad, base.noise.imu_roll_sd_rad);
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

// Every knob added with the solimp, backlash and tracker noise knobs moves a short protocol at its
// probe on both shipped robots (the analysis drops a knob whose probe recording is bit-identical
// to the nominal one as inert).
// The payload's offsets scale with the robot: the built-in robot's leg roots reach 0.225 m
// forward and 0.15 m sideways (probes 0.1 m, range +-0.3 m); the harvestman's 0.18 and 0.12 m.
TEST(Knobs, PayloadOffsetsScaleWithTheLegRootSpan) {
  auto payload = [](const SimConfig& c, KnobKind kind) {
    for (const Knob& k : EnumerateKnobs(c)) {
      if (k.kind == kind) return k;
    }
    return Knob{};
  };
  const SimConfig builtin;
  const SimConfig harvestman = LoadSimConfig(std::string(DGMM_SOURCE_DIR) + "/datasets/robots/harvestman.json");
  const Knob x0 = payload(builtin, KnobKind::kPayloadX), y0 = payload(builtin, KnobKind::kPayloadY);
  const Knob x1 = payload(harvestman, KnobKind::kPayloadX), y1 = payload(harvestman, KnobKind::kPayloadY);
  ASSERT_EQ(x0.probes.size(), 1u);
  EXPECT_NEAR(x0.probes[0], 0.1, 1e-12);
  EXPECT_NEAR(y0.probes[0], 0.1, 1e-12);
  EXPECT_NEAR(x0.hi, 0.3, 1e-12);
  EXPECT_NEAR(y0.lo, -0.3, 1e-12);
  EXPECT_NEAR(x1.probes[0], 0.1 * 0.18 / 0.225, 1e-12);
  EXPECT_NEAR(y1.probes[0], 0.1 * 0.12 / 0.15, 1e-12);
  EXPECT_NEAR(x1.hi, 0.3 * 0.18 / 0.225, 1e-12);
}

TEST(Knobs, NewKnobsChangeAShortProtocolOnTheShippedRobots) {
  for (const char* config_path : {"datasets/robots/default.json", "datasets/robots/harvestman.json"}) {
    const SimConfig base = LoadSimConfig(std::string(DGMM_SOURCE_DIR) + "/" + config_path);
    const std::vector<Knob> knobs = EnumerateKnobs(base);
    ProtocolOptions options;
    options.seed = 3;
    options.placements = 2;
    options.executions_per_placement = 2;
    const SampleSet nominal = SimulateWithKnobs(base, options, knobs, {});
    int tested = 0;
    for (size_t k = 0; k < knobs.size(); ++k) {
      const Knob& knob = knobs[k];
      if (knob.family != "backlash" && knob.family != "tracker_noise" && knob.name.rfind("floor.solimp", 0) != 0) {
        continue;
      }
      const SampleSet probe = SimulateWithKnobs(base, options, knobs, {{static_cast<int>(k), knob.probes.at(0)}});
      ASSERT_EQ(probe.x.rows(), nominal.x.rows()) << config_path << " " << knob.name;
      EXPECT_GT((probe.x - nominal.x).cwiseAbs().maxCoeff(), 0) << config_path << " " << knob.name << " is inert";
      ++tested;
    }
    EXPECT_EQ(tested, 4) << config_path;
  }
}


TEST(GroundKnobsTest, TheGroundsOwnShapeIsAKnobOnRoughGroundOnly) {
  const auto names = [](const std::vector<Knob>& knobs) {
    std::vector<std::string> out;
    for (const Knob& k : knobs) {
      if (k.family == "ground") out.push_back(k.name);
    }
    return out;
  };
  SimConfig c;
  EXPECT_TRUE(names(EnumerateKnobs(c)).empty());
  TerrainDescription t;
  t.half_size_m = 2;
  t.rough = {0.01, 0.2};
  t.stones = {0.05, 0.1, 1};
  c.terrain = t;
  const std::vector<Knob> knobs = EnumerateKnobs(c);
  EXPECT_EQ(names(knobs), (std::vector<std::string>{"terrain.rough.rms_scale", "terrain.stones.height_scale"}));
  int stones = -1;
  for (int i = 0; i < static_cast<int>(knobs.size()); ++i) {
    if (knobs[i].name == "terrain.stones.height_scale") stones = i;
  }
  ModelEdit edit;
  const SimConfig higher = ApplyKnobs(c, knobs, {{stones, 2.0}}, &edit);
  EXPECT_DOUBLE_EQ(higher.terrain->stones.height_m, 0.1);
  EXPECT_DOUBLE_EQ(higher.terrain->rough.rms_height_m, 0.01);
  EXPECT_GT(HeightField::Generate(*higher.terrain).max_m(), HeightField::Generate(t).max_m() + 0.03);
  // The same for a robot block's robot.
  SimConfig hexapod = LoadSimConfig(std::string(DGMM_SOURCE_DIR) + "/datasets/robots/hexapod.json");
  hexapod.terrain = t;
  EXPECT_EQ(names(EnumerateKnobs(hexapod)).size(), 2u);
}

}  // namespace
}  // namespace dgmm::sim
