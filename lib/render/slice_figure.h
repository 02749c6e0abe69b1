#pragma once
// The picture of model slices that `dgmm render` writes and `dgmm view` shows: one panel for one
// slice, or A, B and A - B side by side for two (like Figure 3 of Edgington et al.), over one
// shared plot window, with data points overlaid. Both commands build their panels here.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "render/density_grid.h"
#include "render/heat_map.h"
#include "render/model_slice.h"

namespace dgmm {

// Where a slice comes from: the model's kind ("dgmm", "em", ...) and its file (basename shown).
struct SliceSource {
  std::string kind;
  std::string file;
};

struct SliceFigureOptions {
  int contours = 6;                 // contour lines per density panel (0: none)
  int grid = 200;                   // grid points per axis (>= 2)
  int width = 800, height = 640;    // pixels of each panel
  std::string title;                // replaces the default title (of A - B for two slices)
  std::vector<std::string> labels;  // names of A and B (default: kind and file name)
  // Colour scale of the density panels; A and B always share one scale (ShareColorScale).
  HeatMapSpec::ColorScale color_scale = HeatMapSpec::ColorScale::kAuto;
};

// A window that shows where the slice mixtures' mass is and every point (ExtentRange).
PlotRange SliceWindow(const std::vector<const Mixture*>& slices, const Eigen::MatrixX2d& points);

// The panels over `window`: [p] for one slice; [p_A, p_B, p_A - p_B] for two (sources and slices
// of equal length, 1 or 2). Points (rows = (x, y)) are drawn on every panel.
std::vector<HeatMapSpec> SliceHeatMaps(const std::vector<const ModelSlice*>& slices,
                                       const std::vector<SliceSource>& sources,
                                       const Eigen::MatrixX2d& points, const PlotRange& window,
                                       const SliceFigureOptions& options);

}  // namespace dgmm
