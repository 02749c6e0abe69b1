#include "tune/quadratic_surrogate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace dgmm {
namespace {

// A narrow ridge at 45 degrees: y(v) = 100 - 1/2 (v - v*)^T A (v - v*), A = R diag(1, 40) R^T.
// Coordinate-wise ascent crawls along such a ridge; the joint quadratic sees the coupling.
Eigen::MatrixXd RidgeHessian(int dims) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(dims, dims);
  A(0, 0) = 1;
  A(1, 1) = 40;
  const double c = std::cos(M_PI / 4), s = std::sin(M_PI / 4);
  Eigen::MatrixXd R = Eigen::MatrixXd::Identity(dims, dims);
  R(0, 0) = c, R(0, 1) = -s, R(1, 0) = s, R(1, 1) = c;
  return R * A * R.transpose();
}

// The 3-level full factorial on [-1, 1]^dims (3^dims rows).
Eigen::MatrixXd Factorial(int dims) {
  const int n = static_cast<int>(std::pow(3, dims));
  Eigen::MatrixXd V(n, dims);
  for (int j = 0; j < n; ++j) {
    for (int i = 0, r = j; i < dims; ++i, r /= 3) V(j, i) = r % 3 - 1.0;
  }
  return V;
}

Eigen::VectorXd Sample(const Eigen::MatrixXd& V, const Eigen::MatrixXd& A,
                       const Eigen::VectorXd& top, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, noise);
  Eigen::VectorXd y(V.rows());
  for (int j = 0; j < V.rows(); ++j) {
    const Eigen::VectorXd d = V.row(j).transpose() - top;
    y[j] = 100 - 0.5 * d.dot(A * d) + normal(rng);
  }
  return y;
}

// Noise of the evaluations (the fit's scale). Along the ridge the curvature is 1, so noise 0.05
// on 9 (27) points moves the fitted vertex by about 0.04 (sd) along it: kLocate is ~3.5 sd, well
// within the design's spacing (1), and a third of where one cycle of exact coordinate ascent
// from the centre lands (0.53 from the top).
constexpr double kNoise = 0.05;
constexpr double kLocate = 0.15;

TEST(FitAndMaximiseQuadratic, FindsTheTopOfANoisyRotatedRidge) {
  for (int dims : {2, 3}) {
    const Eigen::MatrixXd A = RidgeHessian(dims);
    Eigen::VectorXd top = Eigen::VectorXd::Zero(dims);
    top[0] = 0.6, top[1] = 0.4;
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const Eigen::MatrixXd V = Factorial(dims);
      const SurrogateMaximum m =
          FitAndMaximiseQuadratic(V, Sample(V, A, top, kNoise, seed), kNoise);
      EXPECT_LT((m.v - top).norm(), kLocate) << "dims " << dims << " seed " << seed << "\n"
                                             << m.fit_report;
      EXPECT_NEAR(m.value, 100, 10 * kNoise);
      // Concave by construction, and the coupling is recovered.
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m.q.Hessian());
      EXPECT_LE(eig.eigenvalues().maxCoeff(), 1e-9);
      EXPECT_NEAR(m.q.Hessian()(0, 1), -A(0, 1), 0.1 * std::abs(A(0, 1)));
      // One cycle of exact coordinate ascent from the design's centre lands much farther away.
      Eigen::VectorXd v = Eigen::VectorXd::Zero(dims);
      for (int i = 0; i < dims; ++i) {  // maximise along axis i: A_ii (v_i - top_i) = -sum_j...
        double off = 0;
        for (int j = 0; j < dims; ++j) {
          if (j != i) off += A(i, j) * (v[j] - top[j]);
        }
        v[i] = top[i] - off / A(i, i);
      }
      EXPECT_GT((v - top).norm(), 3 * kLocate);
    }
  }
}

TEST(FitAndMaximiseQuadratic, StaysInTheBoxSpannedByTheEvaluations) {
  // The top is outside the design's box on the first coordinate: the maximiser is on that face.
  const int dims = 2;
  const Eigen::MatrixXd A = RidgeHessian(dims);
  Eigen::VectorXd top(dims);
  top << 3.0, 2.5;
  const Eigen::MatrixXd V = Factorial(dims);
  const SurrogateMaximum m = FitAndMaximiseQuadratic(V, Sample(V, A, top, kNoise, 7), kNoise);
  for (int i = 0; i < dims; ++i) {
    EXPECT_GE(m.v[i], -1 - 1e-12);
    EXPECT_LE(m.v[i], 1 + 1e-12);
  }
  EXPECT_GT(m.v[0], 0.99);  // pushed against the face nearest the top
  EXPECT_EQ(m.box_lo, Eigen::VectorXd::Constant(dims, -1));
  EXPECT_EQ(m.box_hi, Eigen::VectorXd::Constant(dims, 1));
}

TEST(FitAndMaximiseQuadratic, RobustToOneBadEvaluation) {
  const int dims = 2;
  const Eigen::MatrixXd A = RidgeHessian(dims);
  Eigen::VectorXd top(dims);
  top << -0.3, 0.2;
  const Eigen::MatrixXd V = Factorial(dims);
  Eigen::VectorXd y = Sample(V, A, top, kNoise, 3);
  y[2] -= 200;  // one cross-validation gone wrong
  const SurrogateMaximum m = FitAndMaximiseQuadratic(V, y, kNoise);
  EXPECT_LT((m.v - top).norm(), 2 * kLocate);
}

}  // namespace
}  // namespace dgmm
