#pragma once
// A concave quadratic surrogate of a noisy objective in D dimensions, fitted and maximised with
// Ceres (the joint step of `dgmm tune`, lib/tune/tune_k.h):
//   q(v) = a + b^T (v - v0) - 1/2 (v - v0)^T L L^T (v - v0),  L lower-triangular (D x D),
// so the Hessian -L L^T is negative semi-definite by construction (concave for every
// parameter value). v0 is the best evaluation; the fit is robust (Cauchy) least squares on
// (q(v_j) - y_j) / scale; the maximisation is over the box spanned by the evaluations, with
// v = lo + (hi - lo) sigmoid(s) per coordinate (unconstrained in s: no extrapolation).
#include <Eigen/Dense>
#include <string>

namespace dgmm {

// q(v) for one point v (D).
struct QuadraticSurrogate {
  double a = 0;
  Eigen::VectorXd v0, b;  // D
  Eigen::MatrixXd L;      // D x D lower-triangular; Hessian = -L L^T
  double operator()(const Eigen::VectorXd& v) const;
  Eigen::MatrixXd Hessian() const;
};

struct SurrogateMaximum {
  QuadraticSurrogate q;
  Eigen::VectorXd v;               // maximiser of q in [box_lo, box_hi] (D)
  double value = 0;                // q(v)
  Eigen::VectorXd box_lo, box_hi;  // the box spanned by the evaluations (D)
  int fit_points = 0;
  std::string fit_report, maximise_report;  // Ceres BriefReport()s
};

// Number of free parameters of q in D dimensions: 1 + D + D (D + 1) / 2.
int QuadraticSurrogateParameters(int dims);

// Fits q to the rows of V (n x D) with values y (n) and maximises it over the box the rows span.
// n >= 1, scale > 0 (asserted); with fewer rows than parameters the fit is underdetermined and
// Ceres' damping keeps the surrogate near its start (flat, curvature from the spread of y).
SurrogateMaximum FitAndMaximiseQuadratic(const Eigen::MatrixXd& V, const Eigen::VectorXd& y,
                                         double scale);

}  // namespace dgmm
