#include "render/trajectory_fan.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace dgmm {
namespace {

// The q-quantile of v (nearest rank).
double Quantile(std::vector<double> v, double q) {
  const std::size_t at = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + at, v.end());
  return v[at];
}

// The window holding the central 99% of every axis' positions and the start, padded by 8%.
PlotRange FanRange(const std::vector<Eigen::MatrixX2d>& steps, const Eigen::Vector2d& start) {
  PlotRange r{start.x(), start.x(), start.y(), start.y()};
  for (const auto& s : steps) {
    for (int axis = 0; axis < 2; ++axis) {
      std::vector<double> v(s.col(axis).data(), s.col(axis).data() + s.rows());
      const double lo = Quantile(v, 0.005), hi = Quantile(v, 0.995);
      if (axis == 0) r.Include(lo, r.y_min), r.Include(hi, r.y_min);
      if (axis == 1) r.Include(r.x_min, lo), r.Include(r.x_min, hi);
    }
  }
  const double side = std::max({r.x_max - r.x_min, r.y_max - r.y_min, 1e-3});
  const double cx = 0.5 * (r.x_min + r.x_max), cy = 0.5 * (r.y_min + r.y_max), half = 0.54 * side;
  return {cx - half, cx + half, cy - half, cy + half};  // square: distances read the same on both axes
}

// Mean, covariance factor and squared Mahalanobis distances of 2-D points (rows).
struct PointSpread {
  Eigen::RowVector2d mean;
  Eigen::Matrix2d l;
  std::vector<double> d2;
};

PointSpread SpreadOf(const Eigen::MatrixX2d& points) {
  PointSpread s;
  s.mean = points.colwise().mean();
  const Eigen::MatrixX2d centred = points.rowwise() - s.mean;
  Eigen::Matrix2d cov = centred.transpose() * centred / std::max<double>(1, points.rows() - 1);
  // Relative jitter (all points equal: a unit-free tiny circle) so that a fan of one point or
  // on a line still factors.
  const double scale = cov.trace() > 0 ? cov.trace() : 1.0;
  cov.diagonal().array() += 1e-12 * scale;
  const Eigen::LLT<Eigen::Matrix2d> llt(cov);
  s.l = llt.matrixL();
  const Eigen::MatrixX2d u = llt.matrixL().solve(centred.transpose()).transpose();
  s.d2.resize(u.rows());
  for (Eigen::Index i = 0; i < u.rows(); ++i) s.d2[i] = u.row(i).squaredNorm();
  return s;
}

// The ellipse {p : (p - mean)^T C^-1 (p - mean) = r2}, `segments` + 1 points, closed.
Eigen::MatrixX2d Ellipse(const PointSpread& s, double r2, int segments) {
  const double r = std::sqrt(std::max(r2, 0.0));
  Eigen::MatrixX2d ellipse(segments + 1, 2);
  for (int k = 0; k <= segments; ++k) {
    const double t = 2 * M_PI * k / segments;
    ellipse.row(k) = s.mean + (r * s.l * Eigen::Vector2d(std::cos(t), std::sin(t))).transpose();
  }
  return ellipse;
}

}  // namespace

Eigen::MatrixX2d RegionEllipse(const Eigen::MatrixX2d& points, double share, int segments) {
  const PointSpread s = SpreadOf(points);
  return Ellipse(s, Quantile(s.d2, share), segments);
}

HeatMapSpec TrajectoryFan(const std::vector<Eigen::MatrixX2d>& steps, const Eigen::Vector2d& start,
                          const std::string& title, const std::vector<std::vector<double>>& region_r2) {
  HeatMapSpec spec;
  const PlotRange range = FanRange(steps, start);
  constexpr int kCells = 150;
  DensityGrid grid{range, Eigen::MatrixXd::Zero(kCells, kCells)};
  double total = 0;
  for (const auto& s : steps) {
    for (Eigen::Index i = 0; i < s.rows(); ++i) {
      const int cx = static_cast<int>(std::lround((s(i, 0) - range.x_min) / (range.x_max - range.x_min) * (kCells - 1)));
      const int cy = static_cast<int>(std::lround((s(i, 1) - range.y_min) / (range.y_max - range.y_min) * (kCells - 1)));
      if (cx < 0 || cy < 0 || cx >= kCells || cy >= kCells) continue;
      grid.values(cy, cx) += 1;
      total += 1;
    }
  }
  if (total > 0) grid.values /= total;
  spec.background = grid;
  spec.color_scale = HeatMapSpec::ColorScale::kLog;
  spec.value_label = "share of trajectories";
  Eigen::MatrixX2d path(steps.size() + 1, 2), means(steps.size(), 2);
  path.row(0) = start.transpose();
  for (std::size_t k = 0; k < steps.size(); ++k) {
    means.row(k) = steps[k].colwise().mean();
    path.row(k + 1) = means.row(k);
    const PointSpread s = SpreadOf(steps[k]);  // one spread for both regions
    const bool given = k < region_r2.size() && region_r2[k].size() == 2;
    spec.curves.push_back({Ellipse(s, given ? region_r2[k][0] : Quantile(s.d2, 0.5), 64), {255, 255, 255}, 1.5f});
    spec.curves.push_back({Ellipse(s, given ? region_r2[k][1] : Quantile(s.d2, 0.9), 64), {255, 150, 40}, 1.5f});
  }
  spec.curves.push_back({path, {80, 220, 255}, 2.0f});
  spec.points = means;
  spec.point_rgb = std::array<unsigned char, 3>{80, 220, 255};
  spec.title = title;
  spec.x_label = "x (m)";
  spec.y_label = "y (m)";
  spec.width = 800;
  spec.height = 760;
  return spec;
}

ContourOverlay GroundContours(const PlotRange& range, const std::function<double(double, double)>& height) {
  constexpr int kCells = 150;
  ContourOverlay ground{DensityGrid{range, Eigen::MatrixXd::Zero(kCells, kCells)}, 8, {150, 150, 150}, 1.0f,
                        "ground height"};
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) ground.grid.values(j, i) = height(ground.grid.x(i), ground.grid.y(j));
  }
  ground.grid.values.array() -= ground.grid.values.minCoeff();  // levels are drawn as shares of the top
  return ground;
}

}  // namespace dgmm
