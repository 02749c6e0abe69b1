#include "sim2real/quadratic_peak.h"

#include <algorithm>

namespace dgmm::sim2real {

bool QuadraticPeak(const std::vector<Eigen::Vector2d>& pts, double u_max, double* u) {
  if (pts.size() < 3) return false;
  Eigen::MatrixXd a(pts.size(), 3);
  Eigen::VectorXd y(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const double du = pts[i](0);
    a.row(i) << 1, du, du * du;
    y(i) = pts[i](1);
  }
  const Eigen::Vector3d q = a.colPivHouseholderQr().solve(y);
  if (!(q(2) < 0)) return false;
  *u = std::clamp(-q(1) / (2 * q(2)), -u_max, u_max);
  return true;
}

bool QuadraticMaximum(const std::vector<Eigen::Vector3d>& pts, double u_max, double v_max, double* u, double* v) {
  Eigen::MatrixXd a(pts.size(), 6);
  Eigen::VectorXd y(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const double pu = pts[i](0), pv = pts[i](1);
    a.row(i) << 1, pu, pv, pu * pu, pv * pv, pu * pv;
    y(i) = pts[i](2);
  }
  const Eigen::VectorXd q = a.colPivHouseholderQr().solve(y);
  Eigen::Matrix2d h;
  h << 2 * q(3), q(5), q(5), 2 * q(4);
  if (!(h(0, 0) < 0 && h.determinant() > 0)) return false;
  const Eigen::Vector2d s = -h.inverse() * Eigen::Vector2d(q(1), q(2));
  *u = std::clamp(s(0), -u_max, u_max);
  *v = std::clamp(s(1), -v_max, v_max);
  return true;
}

}  // namespace dgmm::sim2real
