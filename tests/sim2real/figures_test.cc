// The sim2real heat map's content: named axes (commands, terrain regions) and one colour scale
// for the before and after panels, robust to one extreme cell.
#include "sim2real/figures.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dgmm::sim2real {
namespace {

TEST(Sim2RealFigures, HeatMapNamesCommandsAndTerrainAndSharesOneScale) {
  Sim2RealResult r;
  r.command_labels = {"+0.5,0,0", "0,+0.5,0", "0,0,+0.5"};
  r.real_commands = {2, 0};
  r.terrain_labels = {"uphill", "flat", "downhill"};
  // Before: a large deficit (86 nats) in one cell; after: at most 8.
  r.heat_before = Eigen::MatrixXd::Constant(2, 3, 4.0);
  r.heat_before(1, 2) = 86;
  r.heat_after = Eigen::MatrixXd::Constant(2, 3, 1.0);
  r.heat_after(0, 0) = -8;
  r.heat_after(1, 1) = NAN;  // no samples
  const DeficitHeatMapContent h = DescribeDeficitHeatMap(r);
  EXPECT_EQ(h.commands, (std::vector<std::string>{"0,0,+0.5", "+0.5,0,0"}));
  EXPECT_EQ(h.terrain, r.terrain_labels);
  EXPECT_NE(h.x_label.find("terrain"), std::string::npos);
  EXPECT_EQ(h.y_label, "command");
  EXPECT_NE(h.value_label.find("nats"), std::string::npos);
  // One scale for both panels: it covers the after panel's extreme and most of before.
  EXPECT_GE(h.color_max, 8.0);
  EXPECT_LE(h.color_max, 86.0);
}

}  // namespace
}  // namespace dgmm::sim2real
