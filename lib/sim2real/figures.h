#pragma once
// PNG figures of the report (through render/, which needs an X display): the command x terrain
// deficit heat map, before and after the knob correction, density maps of p(dx, dy | c, z) of the
// sim model and the knob correction for the worst cells with the real samples overlaid, and the
// held-out log-likelihood bars. Without a correction (locate only) the "before" panels alone.
// Degrades to no figures and a note.
#include <filesystem>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/analysis.h"
#include "sim2real/report.h"

namespace dgmm::sim2real {

// What the command x terrain deficit heat map shows, independent of drawing: rows in the table's
// order (top to bottom), columns the terrain regions, one colour range for both panels
// (symmetric, the 99th percentile of |deficit| over before and after together).
struct DeficitHeatMapContent {
  Eigen::MatrixXd before, after;        // commands x terrain regions (NaN: no samples; after empty: no correction)
  std::vector<std::string> commands;    // row names (real commands, table order)
  std::vector<std::string> terrain;     // column names (terrain regions)
  double color_max = 0;                 // shared |deficit| at full blue/red
  std::string x_label, y_label, value_label;
};
DeficitHeatMapContent DescribeDeficitHeatMap(const Analysis& a);

// Writes the PNGs into `dir`; returns them with captions. When figures cannot be drawn (no
// display) returns none and sets *note to one line saying why.
std::vector<ReportFigure> RenderFigures(const Analysis& a, const std::filesystem::path& dir, std::string* note);

}  // namespace dgmm::sim2real
