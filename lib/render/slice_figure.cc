#include "render/slice_figure.h"

#include <array>
#include <cassert>
#include <filesystem>

namespace dgmm {
namespace {

std::string Basename(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

}  // namespace

PlotRange SliceWindow(const std::vector<const Mixture*>& slices, const Eigen::MatrixX2d& points) {
  assert(!slices.empty());
  return ExtentRange(slices, points);
}

std::vector<HeatMapSpec> SliceHeatMaps(const std::vector<const ModelSlice*>& slices,
                                       const std::vector<SliceSource>& sources,
                                       const Eigen::MatrixX2d& points, const PlotRange& window,
                                       const SliceFigureOptions& options) {
  assert(!slices.empty() && slices.size() <= 2 && sources.size() == slices.size());
  const int grid = options.grid;
  if (slices.size() == 1) {
    const ModelSlice& s = *slices[0];
    HeatMapSpec map;
    map.background = MixtureDensityGrid(s.mixture, window, grid, grid);
    if (options.contours > 0) {
      map.contours.push_back({map.background, options.contours, {200, 200, 200}});
    }
    map.points = points;
    map.color_scale = options.color_scale;
    map.title = options.title.empty() ? sources[0].kind + " model " + Basename(sources[0].file) +
                                            ": " + s.description
                                      : options.title;
    map.x_label = s.x_label;
    map.y_label = s.y_label;
    map.width = options.width;
    map.height = options.height;
    return {map};
  }
  std::vector<std::string> labels = options.labels;
  for (size_t i = labels.size(); i < 2; ++i) {
    labels.push_back(sources[i].kind + " " + Basename(sources[i].file));
  }
  std::vector<DensityGrid> grids;
  for (const ModelSlice* s : slices) {
    grids.push_back(MixtureDensityGrid(s->mixture, window, grid, grid));
  }
  std::vector<HeatMapSpec> panels(3);
  const std::array<unsigned char, 3> kA{0, 0, 0}, kB{0, 150, 60}, kGrey{200, 200, 200};
  for (int i = 0; i < 2; ++i) {
    panels[i].background = grids[i];
    if (options.contours > 0) panels[i].contours.push_back({grids[i], options.contours, kGrey});
    panels[i].title = (i == 0 ? "A: " : "B: ") + labels[i];
    panels[i].color_scale = options.color_scale;
  }
  // A and B share one colour scale so equal colours mean equal densities.
  ShareColorScale({&panels[0], &panels[1]});
  HeatMapSpec& d = panels[2];
  d.background = grids[0];
  d.background.values = grids[0].values - grids[1].values;
  d.palette = HeatMapSpec::Palette::kDiverging;
  d.value_label = "A - B (clamped at 99th pct of |A - B|)";
  if (options.contours > 0) {
    d.contours.push_back({grids[0], options.contours, kA, 1.5f, labels[0]});
    d.contours.push_back({grids[1], options.contours, kB, 1.5f, labels[1]});
  }
  d.title = options.title.empty() ? "A - B (red: A higher); contours A black, B green"
                                  : options.title;
  for (auto& p : panels) {
    p.points = points;
    p.x_label = slices[0]->x_label;
    p.y_label = slices[0]->y_label;
    p.width = options.width;
    p.height = options.height;
  }
  return panels;
}

}  // namespace dgmm
