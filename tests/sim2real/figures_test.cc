// The sim2real heat map's content: named axes (commands, terrain regions) and one colour scale
// for the before and after panels, robust to one extreme cell.
#include "sim2real/figures.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dgmm::sim2real {
namespace {

TEST(Sim2RealFigures, HeatMapNamesCommandsAndTerrainAndSharesOneScale) {
  Analysis a;
  a.inputs.command_labels = {"+0.5,0,0", "0,+0.5,0", "0,0,+0.5"};
  a.inputs.real_commands = {2, 0};
  a.baseline.terrain_labels = {"uphill", "flat", "downhill"};
  // Before: a large deficit (86 nats) in one cell; after the knob correction: at most 8.
  a.baseline.before.heat = Eigen::MatrixXd::Constant(2, 3, 4.0);
  a.baseline.before.heat(1, 2) = 86;
  a.knobs_analysed = true;
  a.adequacy.after.heat = Eigen::MatrixXd::Constant(2, 3, 1.0);
  a.adequacy.after.heat(0, 0) = -8;
  a.adequacy.after.heat(1, 1) = NAN;  // no samples
  const DeficitHeatMapContent h = DescribeDeficitHeatMap(a);
  EXPECT_EQ(h.commands, (std::vector<std::string>{"0,0,+0.5", "+0.5,0,0"}));
  EXPECT_EQ(h.terrain, a.baseline.terrain_labels);
  EXPECT_NE(h.x_label.find("terrain"), std::string::npos);
  EXPECT_EQ(h.y_label, "command");
  EXPECT_NE(h.value_label.find("nats"), std::string::npos);
  // One scale for both panels: it covers the after panel's extreme and most of before.
  EXPECT_GE(h.color_max, 8.0);
  EXPECT_LE(h.color_max, 86.0);
  // Without a correction (locate only) there is no "after" panel.
  a.knobs_analysed = false;
  EXPECT_EQ(DescribeDeficitHeatMap(a).after.size(), 0);
}

}  // namespace
}  // namespace dgmm::sim2real
