#include "render/heat_map.h"

#include <vtkAxis.h>
#include <vtkCellArray.h>
#include <vtkChartHistogram2D.h>
#include <vtkColorLegend.h>
#include <vtkColorTransferFunction.h>
#include <vtkContextScene.h>
#include <vtkContourFilter.h>
#include <vtkDiscretizableColorTransferFunction.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkPlotLine.h>
#include <vtkPlotPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "render/heat_map_chart.h"
#include "render/round_ticks.h"
#include "render/text_fit.h"
#include "render/vtk_image.h"
#include "util/error.h"

namespace dgmm {
namespace {

using render_internal::AppendHorizontally;
using render_internal::CaptureView;
using render_internal::MakeOffscreenView;
using render_internal::WritePngAtomically;

// Cell-centred raster: pixel (i, j) of the chart's image covers x_i +- dx/2, y_j +- dy/2.
vtkSmartPointer<vtkImageData> ToImage(const DensityGrid& grid, bool cell_centred) {
  const double dx = (grid.range.x_max - grid.range.x_min) / (grid.nx() - 1);
  const double dy = (grid.range.y_max - grid.range.y_min) / (grid.ny() - 1);
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(grid.nx(), grid.ny(), 1);
  if (cell_centred) {
    image->SetOrigin(grid.range.x_min - dx / 2, grid.range.y_min - dy / 2, 0);
  } else {
    image->SetOrigin(grid.range.x_min, grid.range.y_min, 0);
  }
  image->SetSpacing(dx, dy, 1);
  image->AllocateScalars(VTK_DOUBLE, 1);
  // Scalars are x-fastest, one row of nx per y; grid.values is (ny x nx), so its row-major
  // transpose order is the image's order.
  auto* out = static_cast<double*>(image->GetScalarPointer());
  for (int j = 0; j < grid.ny(); ++j) {
    for (int i = 0; i < grid.nx(); ++i) *out++ = grid.values(j, i);
  }
  return image;
}

// Colours from a 1024-entry table over the ramp's range instead of a search of its stops per
// pixel: VTK maps the 40 000 cells of the raster on every paint, and the search was ~6% of a
// `dgmm view` slider redraw (perf). 1024 levels are finer than the 8-bit channels they feed.
vtkSmartPointer<vtkColorTransferFunction> Discretised() {
  auto tf = vtkSmartPointer<vtkDiscretizableColorTransferFunction>::New();
  tf->DiscretizeOn();
  tf->SetNumberOfValues(1024);
  return tf;
}

// Inferno-like ramp (perceptually uniform, luminance increasing): the densest cell is the
// brightest pixel of the plot area.
vtkSmartPointer<vtkColorTransferFunction> SequentialColours(double lo, double hi) {
  static const double kStops[][4] = {
      {0.00, 0, 0, 4},       {0.13, 31, 12, 72},   {0.25, 85, 15, 109},
      {0.38, 136, 34, 106},  {0.50, 186, 54, 85},  {0.63, 227, 89, 51},
      {0.75, 249, 140, 10},  {0.88, 249, 201, 50}, {1.00, 252, 255, 164}};
  auto tf = Discretised();
  for (const auto& s : kStops) tf->AddRGBPoint(lo + s[0] * (hi - lo), s[1] / 255, s[2] / 255, s[3] / 255);
  tf->Build();
  return tf;
}

// Cool-warm diverging ramp symmetric about 0: blue (A < B), light grey (equal), red (A > B).
vtkSmartPointer<vtkColorTransferFunction> DivergingColours(double max_abs) {
  auto tf = Discretised();
  tf->AddRGBPoint(-max_abs, 59 / 255.0, 76 / 255.0, 192 / 255.0);
  tf->AddRGBPoint(0.0, 0.87, 0.87, 0.87);
  tf->AddRGBPoint(max_abs, 180 / 255.0, 4 / 255.0, 38 / 255.0);
  tf->Build();
  return tf;
}

// Contour segments of the grid as pairs of rows (x0,y0),(x1,y1) for a non-polyline vtkPlotLine.
vtkSmartPointer<vtkTable> ContourSegments(const ContourOverlay& overlay) {
  auto table = vtkSmartPointer<vtkTable>::New();
  auto xs = vtkSmartPointer<vtkFloatArray>::New();
  auto ys = vtkSmartPointer<vtkFloatArray>::New();
  xs->SetName("x");
  ys->SetName("y");
  const double max_value = overlay.grid.values.maxCoeff();
  if (max_value > 0 && overlay.levels > 0) {
    auto contour = vtkSmartPointer<vtkContourFilter>::New();
    contour->SetInputData(ToImage(overlay.grid, false));
    for (int l = 1; l <= overlay.levels; ++l) {
      contour->SetValue(l - 1, max_value * l / (overlay.levels + 1));
    }
    contour->Update();
    vtkPolyData* lines = contour->GetOutput();
    for (vtkIdType c = 0; c < lines->GetNumberOfCells(); ++c) {
      vtkCell* cell = lines->GetCell(c);
      for (vtkIdType k = 0; k + 1 < cell->GetNumberOfPoints(); ++k) {
        for (vtkIdType e : {k, k + 1}) {
          double p[3];
          lines->GetPoint(cell->GetPointId(e), p);
          xs->InsertNextValue(static_cast<float>(p[0]));
          ys->InsertNextValue(static_cast<float>(p[1]));
        }
      }
    }
  }
  table->AddColumn(xs);
  table->AddColumn(ys);
  return table;
}

// Polylines as pairs of rows (x0,y0),(x1,y1) for a non-polyline vtkPlotLine.
vtkSmartPointer<vtkTable> CurveSegments(const CurveOverlay& curve) {
  auto table = vtkSmartPointer<vtkTable>::New();
  auto xs = vtkSmartPointer<vtkFloatArray>::New();
  auto ys = vtkSmartPointer<vtkFloatArray>::New();
  xs->SetName("x");
  ys->SetName("y");
  for (Eigen::Index r = 0; r + 1 < curve.points.rows(); ++r) {
    for (Eigen::Index e : {r, r + 1}) {
      xs->InsertNextValue(static_cast<float>(curve.points(e, 0)));
      ys->InsertNextValue(static_cast<float>(curve.points(e, 1)));
    }
  }
  table->AddColumn(xs);
  table->AddColumn(ys);
  return table;
}

// Round ticks (RoundTicks) on a plot axis; VTK's automatic ticks put up to ~15 labels on an
// axis. The colour bar keeps VTK's ticks, because custom ticks there made the three-panel
// `dgmm view --compare` redraw ~30 ms slower (measured side by side with scripts/bench_viewer.sh's
// benchmark).
void SetRoundTicks(vtkAxis* axis, double lo, double hi, int max_ticks) {
  const std::vector<Tick> ticks = RoundTicks(lo, hi, max_ticks);
  if (ticks.empty()) return;
  auto positions = vtkSmartPointer<vtkDoubleArray>::New();
  auto labels = vtkSmartPointer<vtkStringArray>::New();
  for (const Tick& t : ticks) {
    positions->InsertNextValue(t.value);
    labels->InsertNextValue(t.label);
  }
  axis->SetCustomTickPositions(positions, labels);
}

// Ticks at the centres of equal blocks over [lo, hi], labelled with the names.
void SetCategories(vtkAxis* axis, const std::vector<std::string>& names, double lo, double hi) {
  auto positions = vtkSmartPointer<vtkDoubleArray>::New();
  auto labels = vtkSmartPointer<vtkStringArray>::New();
  const double step = (hi - lo) / static_cast<double>(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    positions->InsertNextValue(lo + (static_cast<double>(i) + 0.5) * step);
    labels->InsertNextValue(names[i]);
  }
  axis->SetCustomTickPositions(positions, labels);
}

// The raster as drawn and its colour range: log10 or quantile ranks for those scales.
struct ColourRaster {
  DensityGrid grid;
  double lo = 0, hi = 1;
  std::string value_label;
};

ColourRaster MakeColourRaster(const HeatMapSpec& spec, HeatMapSpec::ColorScale scale) {
  ColourRaster out{spec.background, 0, 1, spec.value_label};
  const Eigen::MatrixXd& v = spec.background.values;
  if (spec.palette == HeatMapSpec::Palette::kDiverging) {
    out.hi = spec.color_max > 0 ? spec.color_max : RobustAbsScale(v);
    out.lo = -out.hi;
    return out;
  }
  const double top = std::max(spec.color_max > 0 ? spec.color_max : v.maxCoeff(), 1e-300);
  if (scale == HeatMapSpec::ColorScale::kLog) {
    // Floor: 4 decades below the top, or higher when the window's lowest values are (so the
    // ramp is spent on what the window shows).
    std::vector<double> sorted(v.data(), v.data() + v.size());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 100, sorted.end());
    const double floor = std::min(top * 0.5, std::max(top * 1e-4, sorted[sorted.size() / 100]));
    out.grid.values = v.cwiseMax(floor).array().log10().matrix();
    out.lo = std::log10(floor);
    out.hi = std::log10(top);
    out.value_label = "log10 " + spec.value_label;
  } else if (scale == HeatMapSpec::ColorScale::kQuantile) {
    std::vector<double> sorted(v.data(), v.data() + v.size());
    std::sort(sorted.begin(), sorted.end());
    for (Eigen::Index k = 0; k < v.size(); ++k) {
      const auto rank = std::lower_bound(sorted.begin(), sorted.end(), v.data()[k]) - sorted.begin();
      out.grid.values.data()[k] = static_cast<double>(rank) / static_cast<double>(sorted.size() - 1);
    }
    out.lo = 0;
    out.hi = 1;
    out.value_label = spec.value_label + " quantile";
  } else {
    out.lo = 0;
    out.hi = top;
  }
  return out;
}

struct RenderedPanel {
  vtkSmartPointer<vtkImageData> image;
  PlotLayout layout;
};

// Width in pixels of the widest line of `text` drawn with `property` at `font_size`.
double MeasuredWidth(vtkTextProperty* property, const std::string& text, int font_size, int dpi) {
  auto probe = vtkSmartPointer<vtkTextProperty>::New();
  probe->ShallowCopy(property);
  probe->SetFontSize(font_size);
  int box[4] = {0, 0, 0, 0};
  if (!vtkTextRenderer::GetInstance()->GetBoundingBox(probe, text, box, dpi)) {
    return TextWidthPx(text, font_size);
  }
  return box[1] - box[0] + 1;
}

// Category labels of the x axis that overlap their neighbours are wrapped and, if need be, set
// in a smaller font (FitCategoryLabels), measured with the axis' own font; returns true when it
// changed them (the chart must be drawn again).
bool FitXCategories(vtkChartHistogram2D* chart, const HeatMapSpec& spec, int dpi) {
  if (spec.x_categories.empty()) return false;
  vtkAxis* axis = chart->GetAxis(vtkAxis::BOTTOM);
  vtkTextProperty* property = axis->GetLabelProperties();
  const double block = (chart->GetPoint2()[0] - chart->GetPoint1()[0]) /
                       static_cast<double>(spec.x_categories.size());
  constexpr double kGapPx = 6;  // between neighbouring labels
  constexpr int kMinFontSize = 8;
  const int size = property->GetFontSize();
  const FittedLabels fitted = FitCategoryLabels(
      spec.x_categories, block - kGapPx, size, std::min(size, kMinFontSize),
      [&](const std::string& text, int font) { return MeasuredWidth(property, text, font, dpi); });
  if (fitted.labels == spec.x_categories && fitted.font_size == size) return false;
  property->SetFontSize(fitted.font_size);
  SetCategories(axis, fitted.labels, spec.background.range.x_min, spec.background.range.x_max);
  return true;
}

// Where the x axis' category labels landed: per label its pixel box (left, right, bottom, top),
// measured with the axis' font, centred on its tick below the plot.
std::vector<std::array<double, 4>> XTickBoxes(vtkChartHistogram2D* chart, const PlotLayout& layout,
                                              int dpi) {
  std::vector<std::array<double, 4>> boxes;
  vtkAxis* axis = chart->GetAxis(vtkAxis::BOTTOM);
  vtkStringArray* labels = axis->GetTickLabels();
  vtkDoubleArray* positions = axis->GetTickPositions();
  if (labels == nullptr || positions == nullptr) return boxes;
  vtkTextProperty* property = axis->GetLabelProperties();
  for (vtkIdType k = 0; k < labels->GetNumberOfValues(); ++k) {
    const std::string text = labels->GetValue(k);
    int box[4] = {0, 0, 0, 0};
    vtkTextRenderer::GetInstance()->GetBoundingBox(property, text, box, dpi);
    const double width = box[1] - box[0] + 1, height = box[3] - box[2] + 1;
    const double centre = layout.ToPixel(positions->GetValue(k), layout.range.y_min).x();
    boxes.push_back(
        {centre - width / 2, centre + width / 2, layout.bottom - 5 - height, layout.bottom - 5});
  }
  return boxes;
}

RenderedPanel RenderPanel(const HeatMapSpec& spec) {
  if (std::string problem = spec.Validate(); !problem.empty()) {
    throw MakeInputError("", "heat map", problem);
  }
  auto view = MakeOffscreenView(spec.width, spec.height);
  vtkSmartPointer<vtkChartHistogram2D> chart = render_internal::MakeHeatMapChart(spec);
  view->GetScene()->AddItem(chart);
  RenderedPanel out;
  out.image = CaptureView(view);
  // The plot's width is known once drawn: labels too wide for their block are refitted.
  const int dpi = view->GetRenderWindow()->GetDPI();
  if (FitXCategories(chart, spec, dpi)) out.image = CaptureView(view);
  out.layout = render_internal::ChartLayout(chart, spec);
  if (!spec.x_categories.empty()) out.layout.x_tick_boxes = XTickBoxes(chart, out.layout, dpi);
  return out;
}

bool AllFinite(const Eigen::MatrixXd& m) { return m.size() == 0 || m.allFinite(); }

}  // namespace

namespace render_internal {

vtkSmartPointer<vtkChartHistogram2D> MakeHeatMapChart(const HeatMapSpec& spec) {
  auto chart = vtkSmartPointer<vtkChartHistogram2D>::New();
  const DensityGrid& bg = spec.background;
  const ColourRaster raster = MakeColourRaster(spec, ResolveColorScale(spec));
  chart->SetInputData(ToImage(raster.grid, true));
  if (spec.palette == HeatMapSpec::Palette::kSequential) {
    chart->SetTransferFunction(SequentialColours(raster.lo, raster.hi));
  } else {
    chart->SetTransferFunction(DivergingColours(raster.hi));
  }
  if (auto* legend = vtkColorLegend::SafeDownCast(chart->GetLegend())) {
    legend->SetTitle(raster.value_label);
  }
  chart->SetShowLegend(true);
  // The legend takes about 110 px on the right; the title is centred on the whole image.
  const auto [title_text, title_size] = FitTitle(spec.title, spec.width);
  chart->SetTitle(title_text);
  chart->GetTitleProperties()->SetFontSize(title_size);
  chart->GetTitleProperties()->SetBold(true);

  for (const ContourOverlay& overlay : spec.contours) {
    auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
    line->SetInputData(ContourSegments(overlay), 0, 1);
    line->SetPolyLine(false);
    line->SetColor(overlay.rgb[0], overlay.rgb[1], overlay.rgb[2], 255);
    line->SetWidth(overlay.width);
    line->SetLabel(overlay.label);
  }
  for (const CurveOverlay& curve : spec.curves) {
    auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
    line->SetInputData(CurveSegments(curve), 0, 1);
    line->SetPolyLine(false);
    line->SetColor(curve.rgb[0], curve.rgb[1], curve.rgb[2], 255);
    line->SetWidth(curve.width);
  }
  if (spec.points.rows() > 0) {
    auto table = vtkSmartPointer<vtkTable>::New();
    auto xs = vtkSmartPointer<vtkDoubleArray>::New();
    auto ys = vtkSmartPointer<vtkDoubleArray>::New();
    xs->SetName("data x");
    ys->SetName("data y");
    for (Eigen::Index r = 0; r < spec.points.rows(); ++r) {
      xs->InsertNextValue(spec.points(r, 0));
      ys->InsertNextValue(spec.points(r, 1));
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    auto* points = vtkPlotPoints::SafeDownCast(chart->AddPlot(vtkChart::POINTS));
    points->SetInputData(table, 0, 1);
    points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
    points->SetMarkerSize(spec.point_size);
    const std::array<unsigned char, 3> rgb = spec.point_rgb.value_or(
        spec.palette == HeatMapSpec::Palette::kSequential ? std::array<unsigned char, 3>{0, 230, 255}
                                                          : std::array<unsigned char, 3>{0, 0, 0});
    points->SetColor(rgb[0], rgb[1], rgb[2], 255);
  }

  vtkAxis* x_axis = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y_axis = chart->GetAxis(vtkAxis::LEFT);
  x_axis->SetTitle(spec.x_label);
  y_axis->SetTitle(spec.y_label);
  for (vtkAxis* axis : {x_axis, y_axis}) axis->SetBehavior(vtkAxis::FIXED);
  x_axis->SetRange(bg.range.x_min, bg.range.x_max);
  y_axis->SetRange(bg.range.y_min, bg.range.y_max);
  if (!spec.x_categories.empty()) {
    SetCategories(x_axis, spec.x_categories, bg.range.x_min, bg.range.x_max);
  } else {
    SetRoundTicks(x_axis, bg.range.x_min, bg.range.x_max, std::max(4, spec.width / 80));
  }
  if (!spec.y_categories.empty()) {
    SetCategories(y_axis, spec.y_categories, bg.range.y_min, bg.range.y_max);
  } else {
    SetRoundTicks(y_axis, bg.range.y_min, bg.range.y_max, std::max(4, spec.height / 50));
  }

  return chart;
}

PlotLayout ChartLayout(vtkChartHistogram2D* chart, const HeatMapSpec& spec) {
  PlotLayout layout;
  const int* p1 = chart->GetPoint1();
  const int* p2 = chart->GetPoint2();
  vtkAxis* x_axis = chart->GetAxis(vtkAxis::BOTTOM);
  vtkAxis* y_axis = chart->GetAxis(vtkAxis::LEFT);
  layout.range = spec.background.range;
  layout.left = p1[0];
  layout.bottom = p1[1];
  layout.right = p2[0];
  layout.top = p2[1];
  layout.width = spec.width;
  layout.height = spec.height;
  layout.x_title = x_axis->GetTitle();
  layout.y_title = y_axis->GetTitle();
  layout.title = chart->GetTitle();
  auto ticks = [](vtkAxis* axis) {
    std::vector<std::string> names;
    if (vtkStringArray* labels = axis->GetTickLabels()) {
      for (vtkIdType k = 0; k < labels->GetNumberOfValues(); ++k) names.push_back(labels->GetValue(k));
    }
    return names;
  };
  if (!spec.x_categories.empty()) layout.x_ticks = ticks(x_axis);
  if (!spec.y_categories.empty()) layout.y_ticks = ticks(y_axis);
  layout.title_font_size = FitTitle(spec.title, spec.width).second;
  const HeatMapSpec::ColorScale scale = ResolveColorScale(spec);
  const ColourRaster raster = MakeColourRaster(spec, scale);
  layout.color_min = raster.lo;
  layout.color_max = raster.hi;
  layout.color_scale = scale;
  return layout;
}

}  // namespace render_internal

std::string HeatMapSpec::Validate() const {
  if (width < 200 || height < 150 || width > 8000 || height > 8000) {
    return "image size must be between 200x150 and 8000x8000 pixels";
  }
  if (background.nx() < 2 || background.ny() < 2) return "the grid needs at least 2x2 points";
  if (!background.range.IsValid()) return "the plot range is empty or not finite";
  if (!AllFinite(background.values)) return "the density grid has NaN or infinite values";
  for (const auto& c : contours) {
    if (c.grid.nx() < 2 || c.grid.ny() < 2 || !AllFinite(c.grid.values)) {
      return "a contour grid is too small or not finite";
    }
  }
  if (points.size() > 0 && !points.allFinite()) return "data points have NaN or infinite values";
  for (const auto& c : curves) {
    if (c.points.size() > 0 && !c.points.allFinite()) return "a curve has NaN or infinite points";
  }
  return "";
}

HeatMapSpec::ColorScale ParseColorScale(const std::string& name) {
  if (name == "linear") return HeatMapSpec::ColorScale::kLinear;
  if (name == "log") return HeatMapSpec::ColorScale::kLog;
  if (name == "quantile") return HeatMapSpec::ColorScale::kQuantile;
  if (name == "auto") return HeatMapSpec::ColorScale::kAuto;
  throw MakeInputError("", "--color-scale", "'" + name + "' (expected linear, log, quantile or auto)");
}

HeatMapSpec::ColorScale ResolveColorScale(const HeatMapSpec& spec) {
  if (spec.color_scale != HeatMapSpec::ColorScale::kAuto) return spec.color_scale;
  const Eigen::MatrixXd& v = spec.background.values;
  const double top = spec.color_max > 0 ? spec.color_max : v.maxCoeff();
  if (!(top > 0) || v.size() == 0) return HeatMapSpec::ColorScale::kLinear;
  const double bright = static_cast<double>((v.array() > 0.1 * top).count()) / static_cast<double>(v.size());
  return bright < 0.1 ? HeatMapSpec::ColorScale::kLog : HeatMapSpec::ColorScale::kLinear;
}

void ShareColorScale(const std::vector<HeatMapSpec*>& panels) {
  double top = 0;
  for (const HeatMapSpec* p : panels) top = std::max(top, p->background.values.maxCoeff());
  bool all_log = true;
  for (HeatMapSpec* p : panels) {
    p->color_max = top;
    all_log = all_log && ResolveColorScale(*p) == HeatMapSpec::ColorScale::kLog;
  }
  for (HeatMapSpec* p : panels) {
    if (p->color_scale == HeatMapSpec::ColorScale::kAuto) {
      p->color_scale = all_log ? HeatMapSpec::ColorScale::kLog : HeatMapSpec::ColorScale::kLinear;
    }
  }
}

double RobustAbsScale(const Eigen::MatrixXd& values, double quantile) {
  std::vector<double> a;
  a.reserve(values.size());
  for (Eigen::Index k = 0; k < values.size(); ++k) {
    if (std::isfinite(values.data()[k])) a.push_back(std::abs(values.data()[k]));
  }
  if (a.empty()) return 1e-300;
  const size_t at = std::min(a.size() - 1, static_cast<size_t>(std::ceil(quantile * (a.size() - 1))));
  std::nth_element(a.begin(), a.begin() + at, a.end());
  double scale = a[at];
  if (!(scale > 0)) scale = *std::max_element(a.begin(), a.end());
  return std::max(scale, 1e-300);
}

Eigen::Vector2d PlotLayout::ToPixel(double x, double y) const {
  const double u = (x - range.x_min) / (range.x_max - range.x_min);
  const double v = (y - range.y_min) / (range.y_max - range.y_min);
  return {left + u * (right - left), bottom + v * (top - bottom)};
}

PlotLayout RenderHeatMap(const HeatMapSpec& spec, const std::string& png_path) {
  RenderedPanel panel = RenderPanel(spec);
  WritePngAtomically(panel.image, png_path);
  return panel.layout;
}

std::vector<PlotLayout> RenderHeatMapRow(const std::vector<HeatMapSpec>& panels,
                                         const std::string& png_path) {
  if (panels.empty()) throw MakeInputError(png_path, "", "nothing to render");
  std::vector<vtkSmartPointer<vtkImageData>> images;
  std::vector<PlotLayout> layouts;
  double offset = 0;
  for (const HeatMapSpec& spec : panels) {
    if (spec.height != panels.front().height) {
      throw MakeInputError(png_path, "", "panels of a row must have the same height");
    }
    RenderedPanel panel = RenderPanel(spec);
    panel.layout.left += offset;
    panel.layout.right += offset;
    for (auto& box : panel.layout.x_tick_boxes) box[0] += offset, box[1] += offset;
    offset += spec.width;
    images.push_back(panel.image);
    layouts.push_back(panel.layout);
  }
  for (auto& layout : layouts) layout.width = static_cast<int>(offset);
  WritePngAtomically(AppendHorizontally(images), png_path);
  return layouts;
}

}  // namespace dgmm
