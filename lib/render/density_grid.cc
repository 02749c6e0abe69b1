#include "render/density_grid.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace dgmm {

bool PlotRange::IsValid() const {
  return std::isfinite(x_min) && std::isfinite(x_max) && std::isfinite(y_min) &&
         std::isfinite(y_max) && x_max > x_min && y_max > y_min;
}

void PlotRange::Include(double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  x_min = std::min(x_min, x);
  x_max = std::max(x_max, x);
  y_min = std::min(y_min, y);
  y_max = std::max(y_max, y);
}

Eigen::Vector2i DensityGrid::ArgMax() const {
  Eigen::Index row = 0, col = 0;
  values.maxCoeff(&row, &col);
  return {static_cast<int>(col), static_cast<int>(row)};
}

DensityGrid SampleGrid(const std::function<double(double, double)>& f, const PlotRange& range,
                       int nx, int ny) {
  assert(nx >= 2 && ny >= 2);
  DensityGrid grid;
  grid.range = range;
  grid.values.resize(ny, nx);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) grid.values(j, i) = f(grid.x(i), grid.y(j));
  }
  return grid;
}

DensityGrid MixtureDensityGrid(const Mixture& mixture2d, const PlotRange& range, int nx, int ny) {
  assert(mixture2d.dim() == 2);
  DensityGrid grid;
  grid.range = range;
  grid.values.resize(ny, nx);
  Eigen::MatrixXd points(2, nx);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) points.col(i) << grid.x(i), grid.y(j);
    if (mixture2d.empty()) {
      grid.values.row(j).setZero();
      continue;
    }
    grid.values.row(j) = mixture2d.LogDensity(Eigen::Ref<const Eigen::MatrixXd>(points)).array().exp().transpose();
  }
  return grid;
}

PlotRange MixtureRange(const Mixture& mixture2d, double sigmas) {
  assert(mixture2d.dim() == 2);
  PlotRange range{1, -1, 1, -1};
  if (mixture2d.empty()) return PlotRange{};
  const double total = mixture2d.total_weight();
  bool any = false;
  for (int pass = 0; pass < 2 && !any; ++pass) {
    for (int c = 0; c < mixture2d.size(); ++c) {
      if (pass == 0 && mixture2d.weight(c) < 0.01 * total) continue;
      const Gaussian& g = mixture2d.component(c);
      double sx = sigmas * std::sqrt(g.covariance()(0, 0));
      double sy = sigmas * std::sqrt(g.covariance()(1, 1));
      if (!any) {
        range = {g.mean()(0) - sx, g.mean()(0) + sx, g.mean()(1) - sy, g.mean()(1) + sy};
        any = true;
      } else {
        range.Include(g.mean()(0) - sx, g.mean()(1) - sy);
        range.Include(g.mean()(0) + sx, g.mean()(1) + sy);
      }
    }
  }
  return range;
}

}  // namespace dgmm
