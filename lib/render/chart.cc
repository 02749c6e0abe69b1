#include "render/chart.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkPlotBar.h>
#include <vtkPlotLine.h>
#include <vtkPlotPoints.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "render/text_fit.h"
#include "render/vtk_image.h"
#include "util/error.h"

namespace dgmm {
namespace {

using Rgb = std::array<unsigned char, 3>;

// Okabe-Ito colours (distinguishable with colour-vision deficiency).
Rgb SeriesColour(const ChartSeries& s, size_t index) {
  static const Rgb kPalette[] = {{0, 114, 178},  {213, 94, 0},  {0, 158, 115}, {204, 121, 167},
                                 {230, 159, 0},  {86, 180, 233}, {0, 0, 0},    {240, 228, 66}};
  return s.rgb ? *s.rgb : kPalette[index % 8];
}

vtkSmartPointer<vtkTable> XyTable(const std::vector<double>& x, const std::vector<double>& y,
                                  const std::string& y_name) {
  auto table = vtkSmartPointer<vtkTable>::New();
  auto xs = vtkSmartPointer<vtkDoubleArray>::New();
  auto ys = vtkSmartPointer<vtkDoubleArray>::New();
  xs->SetName("x");
  ys->SetName(y_name.empty() ? "y" : y_name.c_str());
  for (size_t i = 0; i < x.size(); ++i) {
    xs->InsertNextValue(x[i]);
    ys->InsertNextValue(y[i]);
  }
  table->AddColumn(xs);
  table->AddColumn(ys);
  return table;
}

// Vertical segments y +- err at each x with small horizontal caps, as a segment-pair line plot.
void AddErrorBars(vtkChartXY* chart, const std::vector<double>& x, const std::vector<double>& y,
                  const std::vector<double>& err, double cap, Rgb rgb) {
  if (err.empty()) return;
  std::vector<double> xs, ys;
  auto segment = [&](double x0, double y0, double x1, double y1) {
    xs.insert(xs.end(), {x0, x1});
    ys.insert(ys.end(), {y0, y1});
  };
  for (size_t i = 0; i < x.size(); ++i) {
    const double lo = y[i] - err[i], hi = y[i] + err[i];
    segment(x[i], lo, x[i], hi);
    segment(x[i] - cap, lo, x[i] + cap, lo);
    segment(x[i] - cap, hi, x[i] + cap, hi);
  }
  auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
  line->SetInputData(XyTable(xs, ys, "error"), 0, 1);
  line->SetPolyLine(false);
  line->SetColor(rgb[0], rgb[1], rgb[2], 255);
  line->SetWidth(1.0);
  line->SetLegendVisibility(false);
}

void StyleChart(vtkChartXY* chart, const std::string& title, const std::string& x_label,
                const std::string& y_label, bool legend, int width) {
  const auto [text, size] = FitTitle(title, width);
  chart->SetTitle(text);
  chart->GetTitleProperties()->SetFontSize(size);
  chart->GetTitleProperties()->SetBold(true);
  chart->GetAxis(vtkAxis::BOTTOM)->SetTitle(x_label);
  chart->GetAxis(vtkAxis::LEFT)->SetTitle(y_label);
  chart->SetShowLegend(legend);
  if (legend) {
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  }
}

// The legend goes to the corner (of four) that covers the fewest data points (x, y in axis
// units): a corner box is 45% of the width and 30% of the height of the data range.
void PlaceLegendInEmptiestCorner(vtkChartXY* chart, const std::vector<std::pair<double, double>>& pts) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& [x, y] : pts) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  const double w = std::max(x1 - x0, 1e-300), h = std::max(y1 - y0, 1e-300);
  int best = 0, best_count = INT32_MAX;
  for (int corner = 0; corner < 4; ++corner) {  // top-right, top-left, bottom-right, bottom-left
    const bool right = corner % 2 == 0, top = corner < 2;
    int count = 0;
    for (const auto& [x, y] : pts) {
      const double u = (x - x0) / w, v = (y - y0) / h;
      count += (right ? u > 0.55 : u < 0.45) && (top ? v > 0.7 : v < 0.3);
    }
    if (count < best_count) best = corner, best_count = count;
  }
  chart->GetLegend()->SetHorizontalAlignment(best % 2 == 0 ? vtkChartLegend::RIGHT : vtkChartLegend::LEFT);
  chart->GetLegend()->SetVerticalAlignment(best < 2 ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
}

// Ticks at the decades 10^e covering [lo, hi] on an axis that shows log10 of the values.
void SetDecadeTicks(vtkAxis* axis, double lo, double hi) {
  auto positions = vtkSmartPointer<vtkDoubleArray>::New();
  auto labels = vtkSmartPointer<vtkStringArray>::New();
  for (int e = static_cast<int>(std::floor(std::log10(lo))); e <= std::ceil(std::log10(hi)); ++e) {
    positions->InsertNextValue(e);
    char text[32];
    std::snprintf(text, sizeof(text), "%g", std::pow(10.0, e));
    labels->InsertNextValue(text);
  }
  axis->SetCustomTickPositions(positions, labels);
}

std::string ValidateSeries(const ChartSeries& s, size_t expected_size, bool check_x) {
  const std::string name = "series '" + s.name + "'";
  if (s.y.empty()) return name + " is empty";
  if (check_x && s.x.size() != s.y.size()) return name + ": x and y differ in length";
  if (!check_x && s.y.size() != expected_size) return name + ": needs one value per category";
  if (!s.y_error.empty() && s.y_error.size() != s.y.size()) {
    return name + ": y_error must be empty or as long as y";
  }
  for (const auto* v : {&s.x, &s.y, &s.y_error}) {
    for (double d : *v) {
      if (!std::isfinite(d)) return name + " has NaN or infinite values";
    }
  }
  return "";
}

std::string ValidateSize(int width, int height) {
  if (width < 200 || height < 150 || width > 8000 || height > 8000) {
    return "image size must be between 200x150 and 8000x8000 pixels";
  }
  return "";
}

}  // namespace

std::string LineChartSpec::Validate() const {
  if (auto e = ValidateSize(width, height); !e.empty()) return e;
  if (series.empty()) return "no series to draw";
  for (const auto& s : series) {
    if (auto e = ValidateSeries(s, 0, true); !e.empty()) return e;
    for (double v : s.x) {
      if (log_x && v <= 0) return "series '" + s.name + "': log x axis needs x > 0";
    }
    for (size_t i = 0; i < s.y.size(); ++i) {
      double lo = s.y[i] - (s.y_error.empty() ? 0 : s.y_error[i]);
      if (log_y && lo <= 0) return "series '" + s.name + "': log y axis needs y - error > 0";
    }
  }
  return "";
}

std::string BarChartSpec::Validate() const {
  if (auto e = ValidateSize(width, height); !e.empty()) return e;
  if (categories.empty() || series.empty()) return "no categories or no series to draw";
  for (const auto& s : series) {
    if (auto e = ValidateSeries(s, categories.size(), false); !e.empty()) return e;
  }
  return "";
}

void RenderLineChart(const LineChartSpec& spec, const std::string& png_path) {
  if (auto e = spec.Validate(); !e.empty()) throw MakeInputError(png_path, "line chart", e);
  auto view = render_internal::MakeOffscreenView(spec.width, spec.height);
  auto chart = vtkSmartPointer<vtkChartXY>::New();
  view->GetScene()->AddItem(chart);
  StyleChart(chart, spec.title, spec.x_label, spec.y_label, spec.series.size() > 1, spec.width);
  double x_min = INFINITY, x_max = -INFINITY;
  for (const auto& s : spec.series) {
    for (double v : s.x) x_min = std::min(x_min, v), x_max = std::max(x_max, v);
  }
  // Log axes are drawn as log10 of the values with decade tick labels (VTK 9.1's own log axis
  // crashes on some ranges).
  auto axis_value = [](double v, bool log) { return log ? std::log10(v) : v; };
  std::vector<std::pair<double, double>> plotted;  // every point, in axis units
  for (size_t i = 0; i < spec.series.size(); ++i) {
    ChartSeries s = spec.series[i];
    if (spec.log_y && !s.y_error.empty()) {
      // Symmetric bars in log space: log10(y) +- (log10(y + e) - log10(y - e)) / 2.
      for (size_t j = 0; j < s.y.size(); ++j) {
        s.y_error[j] = 0.5 * (std::log10(s.y[j] + s.y_error[j]) - std::log10(s.y[j] - s.y_error[j]));
      }
    }
    for (double& v : s.x) v = axis_value(v, spec.log_x);
    for (double& v : s.y) v = axis_value(v, spec.log_y);
    for (size_t j = 0; j < s.x.size(); ++j) plotted.emplace_back(s.x[j], s.y[j]);
    const Rgb rgb = SeriesColour(spec.series[i], i);
    auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
    line->SetInputData(XyTable(s.x, s.y, s.name), 0, 1);
    line->SetColor(rgb[0], rgb[1], rgb[2], 255);
    line->SetWidth(2.0);
    line->SetLabel(s.name);
    line->SetMarkerStyle(spec.markers ? vtkPlotPoints::CIRCLE : vtkPlotPoints::NONE);
    // Caps 1% of the x span wide.
    const double cap = 0.01 * std::max(axis_value(x_max, spec.log_x) - axis_value(x_min, spec.log_x),
                                       1e-12);
    AddErrorBars(chart, s.x, s.y, s.y_error, cap, rgb);
  }
  if (spec.series.size() > 1) PlaceLegendInEmptiestCorner(chart, plotted);
  if (spec.log_x) SetDecadeTicks(chart->GetAxis(vtkAxis::BOTTOM), x_min, x_max);
  if (spec.log_y) {
    double y_min = INFINITY, y_max = -INFINITY;
    for (const auto& s : spec.series) {
      for (size_t j = 0; j < s.y.size(); ++j) {
        const double e = s.y_error.empty() ? 0.0 : s.y_error[j];
        y_min = std::min(y_min, s.y[j] - e), y_max = std::max(y_max, s.y[j] + e);
      }
    }
    SetDecadeTicks(chart->GetAxis(vtkAxis::LEFT), y_min, y_max);
  }
  render_internal::WritePngAtomically(render_internal::CaptureView(view), png_path);
}

void RenderBarChart(const BarChartSpec& spec, const std::string& png_path) {
  if (auto e = spec.Validate(); !e.empty()) throw MakeInputError(png_path, "bar chart", e);
  auto view = render_internal::MakeOffscreenView(spec.width, spec.height);
  auto chart = vtkSmartPointer<vtkChartXY>::New();
  view->GetScene()->AddItem(chart);
  StyleChart(chart, spec.title, spec.x_label, spec.y_label, spec.series.size() > 1, spec.width);
  const float fraction = chart->GetBarWidthFraction();
  const size_t n = spec.series.size();
  std::vector<double> index(spec.categories.size());
  for (size_t c = 0; c < index.size(); ++c) index[c] = static_cast<double>(c);
  for (size_t i = 0; i < n; ++i) {
    const ChartSeries& s = spec.series[i];
    const Rgb rgb = SeriesColour(s, i);
    auto* bar = vtkPlotBar::SafeDownCast(chart->AddPlot(vtkChart::BAR));
    bar->SetInputData(XyTable(index, s.y, s.name), 0, 1);
    bar->SetColor(rgb[0], rgb[1], rgb[2], 255);
    bar->SetLabel(s.name);
  }
  // Error bars on top of the bars: vtkChartXY puts bar i of n at x + (i - (n-1)/2) * w / n with w
  // the bar width fraction; drawn after all bars so they stay visible.
  for (size_t i = 0; i < n; ++i) {
    const ChartSeries& s = spec.series[i];
    std::vector<double> x(index);
    const double shift = (static_cast<double>(i) - (n - 1) / 2.0) * fraction / n;
    for (double& v : x) v += shift;
    AddErrorBars(chart, x, s.y, s.y_error, 0.15 * fraction / n, {0, 0, 0});
  }
  auto positions = vtkSmartPointer<vtkDoubleArray>::New();
  auto labels = vtkSmartPointer<vtkStringArray>::New();
  for (size_t c = 0; c < spec.categories.size(); ++c) {
    positions->InsertNextValue(static_cast<double>(c));
    labels->InsertNextValue(spec.categories[c]);
  }
  vtkAxis* x_axis = chart->GetAxis(vtkAxis::BOTTOM);
  x_axis->SetCustomTickPositions(positions, labels);
  x_axis->SetBehavior(vtkAxis::FIXED);
  x_axis->SetRange(-0.6, spec.categories.size() - 0.4);
  render_internal::WritePngAtomically(render_internal::CaptureView(view), png_path);
}

}  // namespace dgmm
