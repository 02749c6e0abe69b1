#include "core/mixture.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core_test_utils.h"

namespace dgmm {
namespace {

using testing::RandomSpd;
using testing::RandomVector;

// Round-off on a handful of components in a few dimensions.
constexpr double kTol = 1e-10;

Mixture RandomMixture(int d, int k, std::mt19937_64& rng, double spread = 3.0) {
  Mixture m(d);
  std::uniform_real_distribution<double> weight(1.0, 10.0);
  for (int i = 0; i < k; ++i)
    m.Add(weight(rng), Gaussian(RandomVector(d, rng, spread), RandomSpd(d, rng)));
  return m;
}

// log(sum_i w_i N_i(x) / sum w), densities multiplied out directly.
double BruteForceLogDensity(const Mixture& m, const Eigen::VectorXd& x) {
  double p = 0;
  for (int i = 0; i < m.size(); ++i) p += m.weight(i) * std::exp(m.component(i).LogDensity(x));
  return std::log(p / m.total_weight());
}

TEST(MixtureTest, LogDensityEqualsBruteForce) {
  std::mt19937_64 rng(0);
  const Mixture m = RandomMixture(3, 4, rng);
  for (int t = 0; t < 20; ++t) {
    const Eigen::VectorXd x = RandomVector(3, rng, 3.0);
    EXPECT_NEAR(m.LogDensity(x), BruteForceLogDensity(m, x), kTol);
  }
  Eigen::MatrixXd X(3, 5);
  for (int j = 0; j < 5; ++j) X.col(j) = RandomVector(3, rng, 3.0);
  const Eigen::VectorXd batch = m.LogDensity(X);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(batch[j], m.LogDensity(X.col(j)), kTol);
}

TEST(MixtureTest, LogDensityFiniteWhereDensitiesUnderflow) {
  Mixture m(1);
  m.Add(1, Gaussian(Eigen::VectorXd::Constant(1, 0.0), Eigen::MatrixXd::Identity(1, 1)));
  m.Add(3, Gaussian(Eigen::VectorXd::Constant(1, 10.0), Eigen::MatrixXd::Identity(1, 1)));
  const Eigen::VectorXd far = Eigen::VectorXd::Constant(1, 100.0);  // exp(-4050) == 0
  const double expected = std::log(3.0 / 4.0) + m.component(1).LogDensity(far);
  EXPECT_NEAR(m.LogDensity(far), expected, 1e-9);
  EXPECT_TRUE(std::isinf(Mixture(2).LogDensity(Eigen::Vector2d(0, 0))));
}

TEST(MixtureTest, ResponsibilitiesSumToOne) {
  std::mt19937_64 rng(1);
  const Mixture m = RandomMixture(2, 5, rng);
  const Eigen::VectorXd x = RandomVector(2, rng);
  const Eigen::VectorXd log_r = m.LogResponsibilities(x);
  EXPECT_NEAR(log_r.array().exp().sum(), 1.0, kTol);
  for (int i = 0; i < m.size(); ++i) {
    EXPECT_NEAR(log_r[i],
                std::log(m.weight(i)) + m.component(i).LogDensity(x) - std::log(m.total_weight()) -
                    m.LogDensity(x),
                kTol);
  }
}

TEST(MixtureTest, MarginalIsMixtureOfMarginals) {
  std::mt19937_64 rng(2);
  const Mixture m = RandomMixture(4, 3, rng);
  const Mixture marg = m.Marginal({2, 0});
  ASSERT_EQ(marg.dim(), 2);
  ASSERT_EQ(marg.size(), 3);
  const Eigen::Vector2d x(0.3, -0.7);
  double p = 0;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(marg.weight(i), m.weight(i));
    p += m.weight(i) * std::exp(m.component(i).Marginal({2, 0}).LogDensity(x));
  }
  EXPECT_NEAR(marg.LogDensity(x), std::log(p / m.total_weight()), kTol);
}

TEST(MixtureTest, ConditionalIsJointOverMarginal) {
  // Eq. 15: p(a | b) = p(a, b) / p(b) for every a, which fixes the re-weighting of eqs. 16-19.
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const Mixture m = RandomMixture(4, 3, rng, 2.0);
    const std::vector<int> b = {1, 3};
    const Eigen::VectorXd values = RandomVector(2, rng);
    const Mixture c = m.Conditional(b, values);
    ASSERT_EQ(c.dim(), 2);
    const double log_pb = m.Marginal(b).LogDensity(values);
    for (int t = 0; t < 5; ++t) {
      const Eigen::VectorXd a = RandomVector(2, rng);
      Eigen::VectorXd y(4);
      y << a[0], values[0], a[1], values[1];
      EXPECT_NEAR(c.LogDensity(a), m.LogDensity(y) - log_pb, kTol);
    }
  }
}

TEST(MixtureTest, ConditionalFarFromEveryComponentKeepsTheNearest) {
  Mixture m(2);
  m.Add(1, Gaussian(Eigen::Vector2d(0, 0), Eigen::MatrixXd::Identity(2, 2)));
  m.Add(1, Gaussian(Eigen::Vector2d(5, 5), Eigen::MatrixXd::Identity(2, 2)));
  // N_i(z = 1000) underflows to 0 for both; the conditional must still be a proper mixture.
  const Mixture c = m.Conditional({1}, Eigen::VectorXd::Constant(1, 1000.0));
  ASSERT_GE(c.size(), 1);
  EXPECT_TRUE(std::isfinite(c.LogDensity(Eigen::VectorXd::Constant(1, 5.0))));
  EXPECT_NEAR(c.component(c.size() - 1).mean()[0], 5.0, 1e-12);
}

TEST(MixtureTest, AffineMapsEveryComponent) {
  std::mt19937_64 rng(4);
  const Mixture m = RandomMixture(2, 3, rng);
  const Eigen::MatrixXd A = 2.0 * Eigen::MatrixXd::Identity(2, 2);
  const Eigen::VectorXd b = Eigen::Vector2d(1, 1);
  const Mixture y = m.Affine(A, b);
  const Eigen::Vector2d x(0.2, 0.4);
  // Change of variables: p_y(A x + b) = p_x(x) / |det A|.
  EXPECT_NEAR(y.LogDensity(A * x + b), m.LogDensity(x) - std::log(4.0), kTol);
}

TEST(MixtureTest, SampleFollowsWeights) {
  Mixture m(1);
  m.Add(1, Gaussian(Eigen::VectorXd::Constant(1, -50.0), Eigen::MatrixXd::Identity(1, 1)));
  m.Add(3, Gaussian(Eigen::VectorXd::Constant(1, 50.0), Eigen::MatrixXd::Identity(1, 1)));
  std::mt19937_64 rng(5);
  const Eigen::MatrixXd X = m.Sample(8000, rng);
  const double right = (X.array() > 0).cast<double>().mean();
  // Binomial standard error sqrt(.75 * .25 / 8000) ~ 0.005; 0.025 is five of them.
  EXPECT_NEAR(right, 0.75, 0.025);
}

TEST(MixtureTest, MaxDensityOfOneGaussianIsItsMean) {
  std::mt19937_64 rng(6);
  Mixture m(3);
  m.Add(2, Gaussian(RandomVector(3, rng), RandomSpd(3, rng)));
  const Mixture::Mode mode = m.MaxDensity();
  EXPECT_LE((mode.x - m.component(0).mean()).norm(), 1e-12);
  EXPECT_NEAR(mode.log_density, m.LogDensity(m.component(0).mean()), kTol);
}

TEST(MixtureTest, MaxDensityOfSeparatedMixtureIsNearHeaviestMean) {
  Mixture m(2);
  m.Add(1, Gaussian(Eigen::Vector2d(0, 0), Eigen::MatrixXd::Identity(2, 2)));
  m.Add(5, Gaussian(Eigen::Vector2d(20, 0), Eigen::MatrixXd::Identity(2, 2)));
  m.Add(2, Gaussian(Eigen::Vector2d(0, 20), Eigen::MatrixXd::Identity(2, 2)));
  const Mixture::Mode mode = m.MaxDensity();
  // The other components shift the mode by ~ exp(-200): nothing measurable.
  EXPECT_LE((mode.x - Eigen::Vector2d(20, 0)).norm(), 1e-9);
}

TEST(MixtureTest, MaxDensityAgreesWithDenseGridIn2d) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const Mixture m = RandomMixture(2, 4, rng, 1.5);
    const Mixture::Mode mode = m.MaxDensity();
    double grid_best = -1e300;
    const double step = 0.04;
    for (double u = -8; u <= 8; u += step) {
      for (double v = -8; v <= 8; v += step) {
        grid_best = std::max(grid_best, m.LogDensity(Eigen::Vector2d(u, v)));
      }
    }
    // The mode search is a local method started from every mean: it must reach at least the
    // grid's best (up to the grid's resolution) and never exceed the true density there.
    EXPECT_GE(mode.log_density, grid_best - 1e-9);
    EXPECT_NEAR(mode.log_density, m.LogDensity(mode.x), 1e-12);
    EXPECT_LE(mode.log_density - grid_best, 0.05);  // grid error O(step^2 * curvature)
  }
}

TEST(MixtureTest, EmptyMixtureHasNoMode) {
  EXPECT_TRUE(std::isinf(Mixture(2).MaxDensity().log_density));
}

}  // namespace
}  // namespace dgmm
