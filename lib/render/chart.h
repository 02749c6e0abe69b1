#pragma once
// Line and bar charts (VTK, offscreen, PNG) for curves such as k against the number of
// Gaussians or cross-validation scores. Needs an X display (render/display.h); atomic writes.
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace dgmm {

// One named series: y over x, optional symmetric error bars y +- y_error (empty or same size).
struct ChartSeries {
  std::string name;
  std::vector<double> x, y, y_error;
  std::optional<std::array<unsigned char, 3>> rgb;  // default: a colour-blind-safe palette
};

// Lines (with point markers) over numeric x; log axes on request (values must be > 0).
struct LineChartSpec {
  std::string title, x_label, y_label;
  std::vector<ChartSeries> series;
  bool log_x = false, log_y = false;
  bool markers = true;
  int width = 800, height = 600;
  // Empty when drawable; otherwise what is wrong.
  std::string Validate() const;
};

// Grouped bars: series s has y[c] (and y_error[c]) for each category c; x of the series unused.
struct BarChartSpec {
  std::string title, x_label, y_label;
  std::vector<std::string> categories;
  std::vector<ChartSeries> series;
  int width = 800, height = 600;
  std::string Validate() const;
};

// Write the chart as a PNG of spec.width x spec.height. Throw std::runtime_error when no display
// can be opened and InputError for an invalid spec or an unwritable path.
void RenderLineChart(const LineChartSpec& spec, const std::string& png_path);
void RenderBarChart(const BarChartSpec& spec, const std::string& png_path);

}  // namespace dgmm
