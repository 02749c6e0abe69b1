// lib/sim/self_contact.h through the simulator and the protocol: the hexapod as shipped (legs that
// touch the ground, not each other) walks a diagonal down the slope upright; the same hexapod with
// leg-to-leg contact is caught touching itself, named by its bodies, and the protocol warns.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "sim/protocol.h"
#include "sim/simulator.h"
#include "robot_files.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;
using test::kRobots;

// The hexapod on its 10-degree slope; `self_colliding`: its MJCF with every geom colliding with
// every other (default conaffinity 1), written next to the original so the config's path holds.
SimConfig Hexapod(bool self_colliding, const fs::path& dir) {
  SimConfig c = LoadSimConfig((kRobots / "hexapod.json").string());
  if (!self_colliding) return c;
  std::ifstream in(kRobots / "hexapod.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string from = "contype=\"1\" conaffinity=\"0\"";
  const auto at = xml.find(from);
  if (at == std::string::npos) throw std::runtime_error("hexapod.xml: default contact filter not found");
  xml.replace(at, from.size(), "contype=\"1\" conaffinity=\"1\"");
  fs::create_directories(dir);
  std::ofstream(dir / "hexapod.xml") << xml;
  c.mjcf_path = (dir / "hexapod.xml").string();
  return c;
}

// Facing uphill, backwards and to the left: diagonally down the slope (the walk that tipped the
// self-colliding hexapod over).
const Eigen::Vector3d kDownhillDiagonal(-0.5, 0.5, 0);

TEST(SelfContactTest, TheShippedHexapodWalksTheDiagonalDownhillWithoutTouchingItself) {
  Simulator sim(Hexapod(false, {}));
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  double lowest_cos = 1;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(sim.RunCommand(kDownhillDiagonal, [&](const Simulator& s) {
      lowest_cos = std::min(lowest_cos, s.TorsoPose().rotation(2, 2));
    }, 10), RunOutcome::kCompleted);
  }
  EXPECT_EQ(sim.SelfContactSteps(), 0);
  EXPECT_EQ(sim.SelfContactPair(), "");
  EXPECT_GT(lowest_cos, std::cos(20 * M_PI / 180));  // no rocking
}

TEST(SelfContactTest, AHexapodWhoseLegsMeetIsCaughtAndTheProtocolWarns) {
  const fs::path dir = fs::temp_directory_path() / ("dgmm_self_contact_" + std::to_string(::getpid()));
  const SimConfig c = Hexapod(true, dir);
  {
    Simulator sim(c);
    ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
    sim.RunCommand(kDownhillDiagonal);
    EXPECT_GT(sim.SelfContactSteps(), 0);
    EXPECT_NE(sim.SelfContactPair().find("tibia with"), std::string::npos) << sim.SelfContactPair();
  }
  CellOptions cell;
  cell.command = kDownhillDiagonal;
  cell.placements = 1;
  cell.executions_per_placement = 2;
  SimSummary summary;
  SimulateCell(c, cell, &summary);
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_NE(summary.warnings.back().find("touched each other in"), std::string::npos) << summary.warnings.back();
  EXPECT_GT(summary.self_contact_executions, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dgmm::sim
