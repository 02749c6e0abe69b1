#pragma once
// PNG figures of the report (through render/, which needs an X display): the command x terrain
// deficit heat map, before/after density maps of p(dx, dy | c, z) for the worst regions with the
// real samples overlaid, and the held-out log-likelihood bars. Degrades to no figures and a note.
#include <filesystem>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/pipeline.h"
#include "sim2real/report.h"

namespace dgmm::sim2real {

// What the command x terrain deficit heat map shows, independent of drawing: rows in the table's
// order (top to bottom), columns the terrain regions, one colour range for both panels
// (symmetric, the 99th percentile of |deficit| over before and after together).
struct DeficitHeatMapContent {
  Eigen::MatrixXd before, after;        // commands x terrain regions (NaN: no samples)
  std::vector<std::string> commands;    // row names (real commands, table order)
  std::vector<std::string> terrain;     // column names (terrain regions)
  double color_max = 0;                 // shared |deficit| at full blue/red
  std::string x_label, y_label, value_label;
};
DeficitHeatMapContent DescribeDeficitHeatMap(const Sim2RealResult& result);

// Writes the PNGs into `dir`; returns them with captions. When figures cannot be drawn (no
// display, render not built) returns none and sets *note to one line saying why.
std::vector<ReportFigure> RenderFigures(const Sim2RealResult& result, const SampleSet& sim,
                                        const SampleSet& real, const std::filesystem::path& dir,
                                        std::string* note);

}  // namespace dgmm::sim2real
