#include "render/density_grid.h"

#include <limits>

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

namespace dgmm {
namespace {

// q-quantile of the marginal of axis `a` of a 2-D mixture: sum_k w_k Phi((x - mu_ka) / sd_ka) = q
// solved by bisection.
double MarginalQuantile(const Mixture& m, int a, double q) {
  const double total = m.total_weight();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Gaussian& g : m.components()) {
    const double sd = std::sqrt(g.covariance()(a, a));
    lo = std::min(lo, g.mean()(a) - 12 * sd);
    hi = std::max(hi, g.mean()(a) + 12 * sd);
  }
  auto cdf = [&](double x) {
    double p = 0;
    for (int c = 0; c < m.size(); ++c) {
      const Gaussian& g = m.component(c);
      const double sd = std::sqrt(g.covariance()(a, a));
      p += m.weight(c) * 0.5 * std::erfc(-(x - g.mean()(a)) / (sd * std::sqrt(2.0)));
    }
    return p / total;
  };
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

PlotRange ExtentRange(const std::vector<const Mixture*>& mixtures2d, const Eigen::MatrixX2d& points,
                      double tail, double pad) {
  PlotRange range{1, -1, 1, -1};
  bool any = false;
  auto include = [&](double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    if (!any) {
      range = {x, x, y, y};
      any = true;
    } else {
      range.Include(x, y);
    }
  };
  for (const Mixture* m : mixtures2d) {
    if (m == nullptr || m->empty() || !(m->total_weight() > 0)) continue;
    include(MarginalQuantile(*m, 0, tail), MarginalQuantile(*m, 1, tail));
    include(MarginalQuantile(*m, 0, 1 - tail), MarginalQuantile(*m, 1, 1 - tail));
  }
  for (Eigen::Index i = 0; i < points.rows(); ++i) include(points(i, 0), points(i, 1));
  if (!any) return PlotRange{};
  double px = pad * (range.x_max - range.x_min), py = pad * (range.y_max - range.y_min);
  if (!(px > 0)) px = std::max(1e-9, 0.5 * std::abs(range.x_min));
  if (!(py > 0)) py = std::max(1e-9, 0.5 * std::abs(range.y_min));
  return {range.x_min - px, range.x_max + px, range.y_min - py, range.y_max + py};
}

}  // namespace dgmm
