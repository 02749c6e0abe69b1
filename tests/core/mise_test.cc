#include "core/mise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace dgmm {
namespace {

Eigen::MatrixXd RandomSpdMatrix(int d, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd a(d, d);
  for (int i = 0; i < d * d; ++i) a(i) = n(rng);
  return a * a.transpose() / d + 0.3 * Eigen::MatrixXd::Identity(d, d);
}

Mixture RandomMixture(int d, int k, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.5);
  std::uniform_real_distribution<double> w(0.5, 5.0);
  Mixture m(d);
  for (int i = 0; i < k; ++i) {
    Eigen::VectorXd mean(d);
    for (int j = 0; j < d; ++j) mean(j) = n(rng);
    m.Add(w(rng), Gaussian(mean, RandomSpdMatrix(d, rng)));
  }
  return m;
}

// Midpoint rule of (p - q)^2 on a box that holds all but a negligible tail of both mixtures.
double GridIse(const Mixture& p, const Mixture& q, int n, double half_width) {
  const double h = 2 * half_width / n;
  double sum = 0;
  if (p.dim() == 1) {
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd x = Eigen::VectorXd::Constant(1, -half_width + (i + 0.5) * h);
      double diff = std::exp(p.LogDensity(x)) - std::exp(q.LogDensity(x));
      sum += diff * diff * h;
    }
    return sum;
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      Eigen::Vector2d x(-half_width + (i + 0.5) * h, -half_width + (j + 0.5) * h);
      double diff = std::exp(p.LogDensity(x)) - std::exp(q.LogDensity(x));
      sum += diff * diff * h * h;
    }
  }
  return sum;
}

// Grid quadrature on 400 (1-D: 4000) cells of smooth integrands: a relative error far below 1%.
constexpr double kGridRelTol = 1e-3;

TEST(MiseTest, MatchesGridIntegrationIn1dAnd2d) {
  std::mt19937_64 rng(0);
  for (int d : {1, 2}) {
    for (int trial = 0; trial < 3; ++trial) {
      Mixture p = RandomMixture(d, 3, rng), q = RandomMixture(d, 2, rng);
      const double exact = IntegratedSquaredError(p, q);
      const double grid = GridIse(p, q, d == 1 ? 4000 : 400, 12.0);
      EXPECT_GT(exact, 0);
      EXPECT_NEAR(exact, grid, kGridRelTol * grid) << "d=" << d << " trial=" << trial;
    }
  }
}

TEST(MiseTest, OverlapOfSingleGaussiansIsGaussianAtMeans) {
  std::mt19937_64 rng(3);
  Mixture p(2), q(2);
  Gaussian a(Eigen::Vector2d(0, 1), RandomSpdMatrix(2, rng));
  Gaussian b(Eigen::Vector2d(1, -1), Eigen::Matrix2d::Identity() * 0.5);
  p.Add(7, a);  // unnormalised weights must not matter
  q.Add(0.2, b);
  Gaussian sum(a.mean(), a.covariance() + b.covariance());
  EXPECT_NEAR(LogOverlapIntegral(p, q), sum.LogDensity(b.mean()), 1e-12);
}

TEST(MiseTest, ZeroForIdenticalAndSymmetric) {
  std::mt19937_64 rng(1);
  for (int d : {1, 3, 6}) {
    Mixture p = RandomMixture(d, 4, rng), q = RandomMixture(d, 3, rng);
    EXPECT_NEAR(IntegratedSquaredError(p, p), 0.0, 1e-12 * IntegratedSquaredErrorTerms(p, p).pp);
    EXPECT_DOUBLE_EQ(IntegratedSquaredError(p, q), IntegratedSquaredError(q, p));
    EXPECT_GT(IntegratedSquaredError(p, q), 0.0);
  }
}

TEST(MiseTest, WeightsAreNormalised) {
  std::mt19937_64 rng(2);
  Mixture p = RandomMixture(2, 3, rng), q = RandomMixture(2, 2, rng);
  Mixture p_scaled(2);
  for (int i = 0; i < p.size(); ++i) p_scaled.Add(p.weight(i) * 1000, p.component(i));
  EXPECT_NEAR(IntegratedSquaredError(p, q), IntegratedSquaredError(p_scaled, q), 1e-12);
}

// Under x -> s x in d dimensions densities scale by s^-d, so int (p - q)^2 scales by s^-d.
TEST(MiseTest, ScalesWithInverseVolume) {
  std::mt19937_64 rng(4);
  for (int d : {1, 2, 4}) {
    Mixture p = RandomMixture(d, 3, rng), q = RandomMixture(d, 2, rng);
    const double s = 2.5;
    const Eigen::MatrixXd a = s * Eigen::MatrixXd::Identity(d, d);
    const Eigen::VectorXd b = Eigen::VectorXd::Constant(d, 0.7);  // a shift changes nothing
    const double ise = IntegratedSquaredError(p, q);
    const double scaled = IntegratedSquaredError(p.Affine(a, b), q.Affine(a, b));
    EXPECT_NEAR(scaled, ise * std::pow(s, -d), 1e-10 * ise);
  }
}

TEST(MiseTest, FarApartMixturesGiveSumOfSelfOverlaps) {
  Mixture p(1), q(1);
  p.Add(1, Gaussian(Eigen::VectorXd::Constant(1, -500), Eigen::MatrixXd::Identity(1, 1)));
  q.Add(1, Gaussian(Eigen::VectorXd::Constant(1, 500), Eigen::MatrixXd::Identity(1, 1)));
  // int N(x;0,1)^2 = N(0;0,2) = 1 / (2 sqrt(pi)); the cross term underflows to exactly 0.
  const IseTerms t = IntegratedSquaredErrorTerms(p, q);
  EXPECT_EQ(t.pq, 0.0);
  EXPECT_NEAR(t.ise, 2 * 0.5 / std::sqrt(M_PI), 1e-14);
}

TEST(MiseTest, EmptyMixtureContributesNothing) {
  std::mt19937_64 rng(5);
  Mixture p = RandomMixture(2, 2, rng), empty(2);
  EXPECT_NEAR(IntegratedSquaredError(p, empty), IntegratedSquaredErrorTerms(p, p).pp, 1e-15);
  EXPECT_EQ(IntegratedSquaredError(empty, empty), 0.0);
}

}  // namespace
}  // namespace dgmm
