#pragma once
// Internal to dgmm_render (includes VTK): the one place that turns a HeatMapSpec into a VTK chart.
// `dgmm render` captures it offscreen (heat_map.cc), `dgmm view` shows it in a window
// (viewer_window.cc); both call MakeHeatMapChart, so the window and the PNG cannot drift apart.
#include <vtkChartHistogram2D.h>
#include <vtkSmartPointer.h>

#include "render/heat_map.h"

namespace dgmm::render_internal {

// A chart drawing spec (raster, palette, colour bar, contours, curves, points, axes, title) to be
// added to a context scene of spec.width x spec.height pixels. The spec must be valid
// (spec.Validate() empty).
vtkSmartPointer<vtkChartHistogram2D> MakeHeatMapChart(const HeatMapSpec& spec);

// Where the chart's plot area landed after a render (pixels, bottom-left origin of its scene).
PlotLayout ChartLayout(vtkChartHistogram2D* chart, const HeatMapSpec& spec);

}  // namespace dgmm::render_internal
