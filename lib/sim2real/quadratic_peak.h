#pragma once
// The maxima of the likelihood searches' least-squares quadratics (refine_payload.cc): through the
// scores of recorded points, in one coordinate (a column of masses) or two (mass and offset).
#include <Eigen/Dense>
#include <vector>

namespace dgmm::sim2real {

// The maximum of score = a + b u + c u^2 fitted to the points (u, score), clamped to |u| <= u_max;
// false when fewer than 3 points or the fit is not concave (c >= 0 or not a number).
bool QuadraticPeak(const std::vector<Eigen::Vector2d>& pts, double u_max, double* u);

// The maximum of ll = a + b u + c v + d u^2 + e v^2 + g u v fitted to the points (u, v, ll), within
// |u| <= u_max, |v| <= v_max; false when the fit is not concave.
bool QuadraticMaximum(const std::vector<Eigen::Vector3d>& pts, double u_max, double v_max, double* u, double* v);

}  // namespace dgmm::sim2real
