#pragma once
// A 2-D function sampled on a regular grid: the raster behind heat maps and contour lines.
#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "core/mixture.h"

namespace dgmm {

// Axis-aligned plot window [x_min, x_max] x [y_min, y_max].
struct PlotRange {
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  bool IsValid() const;  // finite and non-empty on both axes
  // Grows the window to contain (x, y).
  void Include(double x, double y);
};

// values(j, i) = f(x_i, y_j) at x_i = x_min + i (x_max - x_min) / (nx - 1), likewise y_j;
// values is ny x nx (row j = one y).
struct DensityGrid {
  PlotRange range;
  Eigen::MatrixXd values;
  int nx() const { return static_cast<int>(values.cols()); }
  int ny() const { return static_cast<int>(values.rows()); }
  double x(int i) const { return range.x_min + i * (range.x_max - range.x_min) / (nx() - 1); }
  double y(int j) const { return range.y_min + j * (range.y_max - range.y_min) / (ny() - 1); }
  // Index of the largest value as (i, j).
  Eigen::Vector2i ArgMax() const;
};

// f sampled on an nx x ny grid (nx, ny >= 2) over the range.
DensityGrid SampleGrid(const std::function<double(double, double)>& f, const PlotRange& range,
                       int nx, int ny);

// p(x, y) of a 2-D mixture on the grid (densities, not logs).
DensityGrid MixtureDensityGrid(const Mixture& mixture2d, const PlotRange& range, int nx, int ny);

// A window that shows the mixture: the union over components of mean +- `sigmas` standard
// deviations per axis (components with < 1% of the weight ignored unless all are).
PlotRange MixtureRange(const Mixture& mixture2d, double sigmas = 3.5);

// The window a reader needs: per axis, the `tail` and 1 - tail quantiles of the mixtures'
// marginals (where the mass is, not mean +- 3.5 sd of every broad component), grown to contain
// every data point, then padded by `pad` of its size on each side. Points are always inside.
PlotRange ExtentRange(const std::vector<const Mixture*>& mixtures2d, const Eigen::MatrixX2d& points,
                      double tail = 0.005, double pad = 0.06);

}  // namespace dgmm
