#pragma once
// The least-squares plane through points: z = a + b x + c y minimising sum (z_i - a - b x_i - c y_i)^2,
// by a column-pivoting QR of [1 x y]. Shared by the simulator (the ground's relief under the feet)
// and prediction (the ground's tilt under a planned pose).
#include <Eigen/Core>
#include <vector>

namespace dgmm {

struct PlaneFit {
  double a = 0, b = 0, c = 0;  // z = a + b x + c y
  double rms_residual = 0;     // sqrt(mean squared residual)
};

// Fewer than three points: the horizontal plane through their mean height (residual of the mean).
PlaneFit FitPlane(const std::vector<Eigen::Vector3d>& points);

}  // namespace dgmm
