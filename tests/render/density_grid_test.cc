#include "render/density_grid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dgmm {
namespace {

Mixture TwoBumps() {
  Mixture m(2);
  m.Add(3, Gaussian(Eigen::Vector2d(1, 2), Eigen::Vector2d(0.3, 0.5).asDiagonal()));
  m.Add(1, Gaussian(Eigen::Vector2d(-1, -1), Eigen::Matrix2d::Identity() * 0.4));
  return m;
}

TEST(DensityGridTest, SampleGridPutsFunctionValuesAtGridPoints) {
  PlotRange range{-1, 3, 10, 12};
  DensityGrid g = SampleGrid([](double x, double y) { return 10 * x + y; }, range, 5, 3);
  ASSERT_EQ(g.nx(), 5);
  ASSERT_EQ(g.ny(), 3);
  EXPECT_DOUBLE_EQ(g.x(0), -1);
  EXPECT_DOUBLE_EQ(g.x(4), 3);
  EXPECT_DOUBLE_EQ(g.y(2), 12);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) EXPECT_DOUBLE_EQ(g.values(j, i), 10 * g.x(i) + g.y(j));
  }
  EXPECT_EQ(g.ArgMax(), Eigen::Vector2i(4, 2));
}

TEST(DensityGridTest, MixtureGridIsTheDensity) {
  const Mixture m = TwoBumps();
  DensityGrid g = MixtureDensityGrid(m, {-3, 3, -3, 4}, 31, 29);
  for (int j = 0; j < g.ny(); j += 7) {
    for (int i = 0; i < g.nx(); i += 5) {
      EXPECT_NEAR(g.values(j, i), std::exp(m.LogDensity(Eigen::Vector2d(g.x(i), g.y(j)))), 1e-14);
    }
  }
  // The grid maximum is the grid point nearest the mode.
  const Mixture::Mode mode = m.MaxDensity();
  const Eigen::Vector2i at = g.ArgMax();
  EXPECT_NEAR(g.x(at(0)), mode.x(0), 6.0 / 30);
  EXPECT_NEAR(g.y(at(1)), mode.x(1), 7.0 / 28);
}

TEST(DensityGridTest, MixtureRangeHoldsEveryComponent) {
  const Mixture m = TwoBumps();
  const PlotRange r = MixtureRange(m, 3.0);
  ASSERT_TRUE(r.IsValid());
  for (const Gaussian& g : m.components()) {
    EXPECT_LE(r.x_min, g.mean()(0) - 3 * std::sqrt(g.covariance()(0, 0)) + 1e-12);
    EXPECT_GE(r.x_max, g.mean()(0) + 3 * std::sqrt(g.covariance()(0, 0)) - 1e-12);
    EXPECT_LE(r.y_min, g.mean()(1) - 3 * std::sqrt(g.covariance()(1, 1)) + 1e-12);
    EXPECT_GE(r.y_max, g.mean()(1) + 3 * std::sqrt(g.covariance()(1, 1)) - 1e-12);
  }
}

TEST(DensityGridTest, RangeValidityAndInclude) {
  PlotRange r{0, 1, 0, 1};
  EXPECT_TRUE(r.IsValid());
  r.Include(5, -2);
  r.Include(NAN, 100);  // ignored
  EXPECT_EQ(r.x_max, 5);
  EXPECT_EQ(r.y_min, -2);
  EXPECT_EQ(r.y_max, 1);
  EXPECT_FALSE((PlotRange{1, 1, 0, 1}.IsValid()));
  EXPECT_FALSE((PlotRange{0, INFINITY, 0, 1}.IsValid()));
}

}  // namespace
}  // namespace dgmm
