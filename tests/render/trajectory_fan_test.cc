// The trajectory fan's geometry (lib/render/trajectory_fan.h): region ellipses and the spec.
#include "render/trajectory_fan.h"

#include <gtest/gtest.h>

#include <random>

namespace dgmm {
namespace {

Eigen::MatrixX2d GaussianPoints(int n, double sx, double sy, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  Eigen::MatrixX2d p(n, 2);
  for (int i = 0; i < n; ++i) p.row(i) << 1 + sx * unit(rng), -2 + sy * unit(rng);
  return p;
}

TEST(TrajectoryFan, RegionEllipsesHaveTheGaussianRadii) {
  const Eigen::MatrixX2d p = GaussianPoints(20000, 2.0, 0.5, 3);
  // For a 2-D Gaussian the share-q region has squared radius -2 log(1 - q) in standard units.
  for (double q : {0.5, 0.9}) {
    const Eigen::MatrixX2d e = RegionEllipse(p, q);
    const double r = std::sqrt(-2 * std::log(1 - q));
    EXPECT_NEAR(e.col(0).maxCoeff() - 1, 2.0 * r, 0.05 * 2.0 * r) << q;
    EXPECT_NEAR(-2 - e.col(1).minCoeff(), 0.5 * r, 0.05 * 0.5 * r) << q;
    EXPECT_TRUE(e.row(0).isApprox(e.row(e.rows() - 1))) << "closed";
  }
}

TEST(TrajectoryFan, TheSpecHasTwoRegionsPerStepAndThePath) {
  const std::vector<Eigen::MatrixX2d> steps = {GaussianPoints(500, 0.1, 0.1, 1),
                                               GaussianPoints(500, 0.2, 0.2, 2).rowwise() + Eigen::RowVector2d(1, 0)};
  const HeatMapSpec spec = TrajectoryFan(steps, Eigen::Vector2d(0, -2), "fan");
  EXPECT_EQ(spec.Validate(), "");
  EXPECT_EQ(spec.curves.size(), 2 * steps.size() + 1);
  EXPECT_EQ(spec.curves.back().points.rows(), 3);  // start and two step means
  EXPECT_NEAR(spec.background.values.sum(), 1.0, 1e-3);  // nearly every trajectory inside the window
  EXPECT_LE(spec.background.range.x_min, 0.0);
}

}  // namespace
}  // namespace dgmm
