// The wiring of lib/sim2real's simulator interface to lib/sim (app/wiring/mujoco_knob_simulator.h).
#include "app/wiring/mujoco_knob_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "sim2real/simulation_cache.h"

namespace dgmm::app {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The second robot in `dir`: robot.xml includes body.xml (harvestman.xml, with the torso's
// half-height replaced by `torso_half_height`); the config is harvestman.json pointing at robot.xml.
sim::SimConfig IncludingRobot(const fs::path& dir, const std::string& torso_half_height) {
  const fs::path robots = fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots";
  fs::create_directories(dir);
  std::string body = ReadText(robots / "harvestman.xml");
  const std::string torso = "size=\"0.22 0.12 0.035\"";
  const auto at = body.find(torso);
  if (at == std::string::npos) throw std::runtime_error("harvestman.xml: torso size not found");
  body.replace(at, torso.size(), "size=\"0.22 0.12 " + torso_half_height + "\"");
  WriteText(dir / "body.xml", body);
  WriteText(dir / "robot.xml", "<mujoco model=\"wrapper\"><include file=\"body.xml\"/></mujoco>\n");
  sim::SimConfig config = sim::LoadSimConfig((robots / "harvestman.json").string());
  config.mjcf_path = (dir / "robot.xml").string();
  return config;
}

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

TEST(MujocoKnobSimulator, FingerprintFollowsIncludedFilesAndNotTheRobotsFolder) {
  const fs::path root = fs::temp_directory_path() / ("dgmm_knob_sim_include_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const MujocoKnobSimulator a(IncludingRobot(root / "a", "0.035"));
  const MujocoKnobSimulator moved(IncludingRobot(root / "moved" / "b", "0.035"));
  const MujocoKnobSimulator edited(IncludingRobot(root / "c", "0.045"));
  fs::remove_all(root);
  EXPECT_EQ(a.Fingerprint(), moved.Fingerprint());
  EXPECT_NE(a.Fingerprint(), edited.Fingerprint());
  // The recording cache keys follow: the edited robot cannot be served the old robot's recordings.
  const sim2real::Recording rec{"paper", 3, 2};
  EXPECT_EQ(sim2real::RecordingKey(a, rec, {}), sim2real::RecordingKey(moved, rec, {}));
  EXPECT_NE(sim2real::RecordingKey(a, rec, {}), sim2real::RecordingKey(edited, rec, {}));
}

TEST(MujocoKnobSimulator, FingerprintFollowsAReplaysRecordingsNotTheirFolder) {
  const fs::path src = fs::path(DGMM_SOURCE_DIR) / "datasets" / "robots" / "mammal_quadruped";
  const fs::path root = fs::temp_directory_path() / ("dgmm_knob_sim_replay_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "moved");
  fs::copy(src, root / "a", fs::copy_options::recursive);
  fs::copy(src, root / "moved" / "b", fs::copy_options::recursive);
  const std::string a = MujocoKnobSimulator(sim::LoadSimConfig((root / "a" / "mammal_quadruped.json").string())).Fingerprint();
  const std::string moved =
      MujocoKnobSimulator(sim::LoadSimConfig((root / "moved" / "b" / "mammal_quadruped.json").string())).Fingerprint();
  std::ofstream(root / "a" / "replay" / "p05_p00_p00.csv", std::ios::app) << "9.000,0,0,0,0,0,0,0,0,0,0,0,0\n";
  const std::string edited = MujocoKnobSimulator(sim::LoadSimConfig((root / "a" / "mammal_quadruped.json").string())).Fingerprint();
  fs::remove_all(root);
  EXPECT_EQ(a, moved);
  EXPECT_NE(a, edited);
}

TEST(MujocoKnobSimulator, RecordCellRepeatsACommandAtOnePlacementAndKnobsChangeIt) {
  const MujocoKnobSimulator sim{sim::SimConfig{}};
  sim2real::Cell cell;
  cell.command = Eigen::Vector3d(0.5, 0, 0);
  cell.terrain = Eigen::Vector2d(0.2, 0.0);
  cell.placements = 1;
  cell.executions_per_placement = 3;
  cell.seed = 5;
  const sim2real::CellRecording a = sim.RecordCell(cell, {});
  const sim2real::CellRecording b = sim.RecordCell(cell, {});
  ASSERT_EQ(a.set.size(), 3);
  EXPECT_EQ(a.set.x, b.set.x);
  EXPECT_NE(a.placement.find("heading"), std::string::npos) << a.placement;
  int friction = -1;
  for (int k = 0; k < static_cast<int>(sim.knobs().size()); ++k) {
    if (sim.knobs()[k].name == "floor.friction.sliding") friction = k;
  }
  ASSERT_GE(friction, 0);
  EXPECT_NE(sim.RecordCell(cell, {{friction, 0.2}}).set.x, a.set.x);
  cell.terrain = Eigen::Vector3d(0.2, 0.0, 0.0);
  EXPECT_THROW(sim.RecordCell(cell, {}), std::exception);
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
