#pragma once
// Density heat maps (VTK charts, offscreen, PNG): a background raster with a colour bar, optional
// contour lines of other rasters, optional data points, named axes and a title. Needs an X display
// (render/display.h); writes through AtomicFile.
#include <Eigen/Dense>
#include <array>
#include <optional>
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
  // How a sequential raster maps to colour: linear in the value; log10 of the value (floored at
  // the window's 1st percentile, at least 1e-4 of the top); quantile (the cell's rank among the grid's cells, so every colour covers
  // the same area); auto: log when the bright part (cells above 10% of the maximum) covers less
  // than 10% of the grid (a peaked model would be a black field with one spot), else linear.
  enum class ColorScale { kLinear, kLog, kQuantile, kAuto };
  DensityGrid background;
  Palette palette = Palette::kSequential;
  ColorScale color_scale = ColorScale::kLinear;
  // > 0: the top of the colour scale, shared by panels that must compare (sequential: the value
  // at the brightest colour; diverging: the |difference| at full blue/red, larger values clamp).
  // 0: from this grid alone (sequential: its maximum; diverging: RobustAbsScale of its values).
  double color_max = 0;
  std::vector<ContourOverlay> contours;
  std::vector<CurveOverlay> curves;  // drawn over the contours, under the points
  Eigen::MatrixX2d points;  // data overlaid as dots (rows = (x, y))
  // Dot colour and size; default colour: cyan on the sequential ramp, black on diverging.
  std::optional<std::array<unsigned char, 3>> point_rgb;
  float point_size = 7;
  std::string title, x_label, y_label, value_label = "density";
  // Category axes: non-empty replaces the numeric ticks by these names at the centres of equal
  // blocks over the range (first name at the low end), e.g. commands or terrain regions.
  std::vector<std::string> x_categories, y_categories;
  int width = 800, height = 600;
  // Empty string when drawable; otherwise what is wrong (sizes, non-finite values, ranges).
  std::string Validate() const;
};

// "linear" | "log" | "quantile" | "auto"; InputError naming --color-scale otherwise.
HeatMapSpec::ColorScale ParseColorScale(const std::string& name);
// The scale a spec's sequential raster is drawn with (kAuto resolved on its values).
HeatMapSpec::ColorScale ResolveColorScale(const HeatMapSpec& spec);
// Puts sequential panels on one colour scale: color_max = the largest maximum, and kAuto resolved
// once for all (log only when every panel would be log), so equal colours mean equal values.
void ShareColorScale(const std::vector<HeatMapSpec*>& panels);
// Robust symmetric scale of a difference raster: the `quantile` of |value| over the cells
// (default 99th percentile, so one spike does not wash out the rest); > 0.
double RobustAbsScale(const Eigen::MatrixXd& values, double quantile = 0.99);

// Where the plot area landed, in image pixels with the origin at the bottom-left (VTK's
// convention; PNG row r from the top is pixel y = height - 1 - r).
struct PlotLayout {
  PlotRange range;
  double left = 0, bottom = 0, right = 0, top = 0;
  int width = 0, height = 0;
  // What was drawn: axis titles, the title lines and the colour scale's range and kind.
  std::string x_title, y_title, title;
  std::vector<std::string> x_ticks, y_ticks;  // tick labels when category axes were drawn
  // With x categories: each label's box as drawn (left, right, bottom, top in pixels, measured
  // with the axis font); labels too wide for their block are wrapped or set smaller so that
  // neighbouring boxes do not overlap.
  std::vector<std::array<double, 4>> x_tick_boxes;
  int title_font_size = 0;
  double color_min = 0, color_max = 0;
  HeatMapSpec::ColorScale color_scale = HeatMapSpec::ColorScale::kLinear;
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
