#pragma once
// The trajectory fan of a prediction (dgmm predict --figure): where the predicted trajectories
// are after each command (a histogram of all steps' positions, log colour), each step's 50% and
// 90% regions as ellipses and the mean path from the start. Plain arrays in: no lib/predict here.
#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "render/heat_map.h"

namespace dgmm {

// The region of the 2-D points (rows) holding `share` of them: the ellipse
// {p : (p - m)^T C^-1 (p - m) <= r^2}, m and C their mean and covariance, r^2 the share-quantile of
// the points' own squared Mahalanobis distances; `segments` + 1 points, closed.
Eigen::MatrixX2d RegionEllipse(const Eigen::MatrixX2d& points, double share, int segments = 64);

// steps[k]: the (x, y) of every trajectory after command k + 1 (rows); start: (x, y) before;
// region_r2[k] (if given): r^2 of step k's 50% and 90% regions (otherwise the points' own quantiles).
HeatMapSpec TrajectoryFan(const std::vector<Eigen::MatrixX2d>& steps, const Eigen::Vector2d& start,
                          const std::string& title, const std::vector<std::vector<double>>& region_r2 = {});

// Height contours of the ground under a fan (grey, 8 levels evenly over the window's height range),
// height(x, y) in metres sampled on a 150 x 150 grid over `range`.
ContourOverlay GroundContours(const PlotRange& range, const std::function<double(double, double)>& height);

}  // namespace dgmm
