#include "core/plane_fit.h"

#include <Eigen/QR>
#include <cmath>

namespace dgmm {

PlaneFit FitPlane(const std::vector<Eigen::Vector3d>& points) {
  const int n = static_cast<int>(points.size());
  PlaneFit fit;
  if (n == 0) return fit;
  Eigen::MatrixXd design(n, 3);
  Eigen::VectorXd z(n);
  for (int i = 0; i < n; ++i) {
    design.row(i) << 1, points[i].x(), points[i].y();
    z[i] = points[i].z();
  }
  Eigen::Vector3d coef(z.mean(), 0, 0);
  if (n >= 3) coef = design.colPivHouseholderQr().solve(z);
  fit.a = coef[0];
  fit.b = coef[1];
  fit.c = coef[2];
  fit.rms_residual = std::sqrt((z - design * coef).squaredNorm() / n);
  return fit;
}

}  // namespace dgmm
