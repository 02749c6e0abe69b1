#pragma once
// Density heat maps (VTK charts, offscreen, PNG): a background raster with a colour bar, optional
// contour lines of other rasters, optional data points, named axes and a title. Needs an X display
// (render/display.h); writes through AtomicFile.
#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "render/density_grid.h"

namespace dgmm {

// Contour lines of `grid` at `levels` evenly spaced fractions of its maximum (1/(L+1)..L/(L+1)).
struct ContourOverlay {
  DensityGrid grid;
  int levels = 6;
  std::array<unsigned char, 3> rgb{255, 255, 255};
  float width = 1.5f;
  std::string label;  // shown in the chart legend when non-empty
};

// A polyline in data units (rows = (x, y)), e.g. a component's ellipse.
struct CurveOverlay {
  Eigen::MatrixX2d points;
  std::array<unsigned char, 3> rgb{255, 255, 255};
  float width = 1.0f;
};

struct HeatMapSpec {
  // Sequential: 0..max on a dark-to-bright ramp (brightest = densest). Diverging: blue-white-red
  // symmetric about 0 (for differences p_A - p_B).
  enum class Palette { kSequential, kDiverging };
  DensityGrid background;
  Palette palette = Palette::kSequential;
  std::vector<ContourOverlay> contours;
  std::vector<CurveOverlay> curves;  // drawn over the contours, under the points
  Eigen::MatrixX2d points;  // data overlaid as small dots (rows = (x, y))
  std::string title, x_label, y_label, value_label = "density";
  int width = 800, height = 600;
  // Empty string when drawable; otherwise what is wrong (sizes, non-finite values, ranges).
  std::string Validate() const;
};

// Where the plot area landed, in image pixels with the origin at the bottom-left (VTK's
// convention; PNG row r from the top is pixel y = height - 1 - r).
struct PlotLayout {
  PlotRange range;
  double left = 0, bottom = 0, right = 0, top = 0;
  int width = 0, height = 0;
  // (x, y) in data units -> pixel coordinates (bottom-left origin).
  Eigen::Vector2d ToPixel(double x, double y) const;
};

// Renders one heat map to a PNG of spec.width x spec.height. Throws std::runtime_error when no
// display can be opened, InputError for an invalid spec or an unwritable path.
PlotLayout RenderHeatMap(const HeatMapSpec& spec, const std::string& png_path);

// Several heat maps side by side in one PNG (left to right; heights must agree); layouts are in
// the coordinates of the combined image.
std::vector<PlotLayout> RenderHeatMapRow(const std::vector<HeatMapSpec>& panels,
                                         const std::string& png_path);

}  // namespace dgmm
