#include "sim2real/quadratic_peak.h"

#include <gtest/gtest.h>

namespace dgmm::sim2real {
namespace {

// Scores of -(u - 0.2)^2 at u = -1, 0, 1 (and a fourth point off the parabola).
TEST(QuadraticPeak, FindsTheMaximumOfAConcaveFit) {
  double u = 0;
  ASSERT_TRUE(QuadraticPeak({{-1, -1.44}, {0, -0.04}, {1, -0.64}}, 0.5, &u));
  EXPECT_NEAR(u, 0.2, 1e-12);
  ASSERT_TRUE(QuadraticPeak({{-1, -1.44}, {-0.5, -0.49}, {0, -0.04}, {1, -0.64}}, 0.5, &u));
  EXPECT_NEAR(u, 0.2, 1e-12);
}

TEST(QuadraticPeak, ClampsToTheGivenReach) {
  double u = 0;
  ASSERT_TRUE(QuadraticPeak({{-1, -4}, {0, -1}, {1, 0}}, 0.5, &u));  // -(u - 1)^2: its peak beyond 0.5
  EXPECT_EQ(u, 0.5);
}

TEST(QuadraticPeak, RefusesAFlatOrConvexFitAndTooFewPoints) {
  double u = 7;
  EXPECT_FALSE(QuadraticPeak({{-1, 1}, {0, 0}, {1, 1}}, 0.5, &u));  // a valley
  EXPECT_FALSE(QuadraticPeak({{-1, -1}, {0, 0}, {1, 1}}, 0.5, &u));  // a line
  EXPECT_FALSE(QuadraticPeak({{-1, -1}, {0, 0}}, 0.5, &u));
  EXPECT_EQ(u, 7);
}

// ll = -(u - 0.3)^2 - 2 (v + 0.4)^2 + 0.5 (u - 0.3)(v + 0.4) on a 3 x 3 grid.
TEST(QuadraticMaximum, FindsTheMaximumOfAConcaveSurfaceAndClamps) {
  std::vector<Eigen::Vector3d> pts;
  for (double u : {-1.0, 0.0, 1.0}) {
    for (double v : {-1.0, 0.0, 1.0}) {
      const double du = u - 0.3, dv = v + 0.4;
      pts.emplace_back(u, v, -du * du - 2 * dv * dv + 0.5 * du * dv);
    }
  }
  double u = 0, v = 0;
  ASSERT_TRUE(QuadraticMaximum(pts, 2, 2, &u, &v));
  EXPECT_NEAR(u, 0.3, 1e-9);
  EXPECT_NEAR(v, -0.4, 1e-9);
  ASSERT_TRUE(QuadraticMaximum(pts, 0.1, 0.2, &u, &v));
  EXPECT_EQ(u, 0.1);
  EXPECT_EQ(v, -0.2);
}

TEST(QuadraticMaximum, RefusesASaddle) {
  std::vector<Eigen::Vector3d> pts;
  for (double u : {-1.0, 0.0, 1.0}) {
    for (double v : {-1.0, 0.0, 1.0}) pts.emplace_back(u, v, -u * u + v * v);
  }
  double u = 0, v = 0;
  EXPECT_FALSE(QuadraticMaximum(pts, 2, 2, &u, &v));
}

}  // namespace
}  // namespace dgmm::sim2real
