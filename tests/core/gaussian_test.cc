#include "core/gaussian.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core_test_utils.h"

namespace dgmm {
namespace {

using testing::RandomSpd;
using testing::RandomVector;

// Round-off on 4-6 dimensional problems with condition numbers of a few tens.
constexpr double kTol = 1e-10;

// log N(x; m, S) from the textbook formula with an explicit inverse and determinant.
double NaiveLogDensity(const Eigen::VectorXd& x, const Eigen::VectorXd& m,
                       const Eigen::MatrixXd& s) {
  const Eigen::VectorXd d = x - m;
  return -0.5 * (x.size() * std::log(2 * std::numbers::pi) + std::log(s.determinant()) +
                 d.dot(s.inverse() * d));
}

TEST(GaussianTest, LogDensityEqualsTextbookFormula) {
  std::mt19937_64 rng(0);
  for (int d : {1, 2, 5}) {
    const Gaussian g(RandomVector(d, rng), RandomSpd(d, rng));
    for (int t = 0; t < 10; ++t) {
      const Eigen::VectorXd x = RandomVector(d, rng, 2.0);
      EXPECT_NEAR(g.LogDensity(x), NaiveLogDensity(x, g.mean(), g.covariance()), kTol);
      const double m2 = (x - g.mean()).dot(g.covariance().inverse() * (x - g.mean()));
      EXPECT_NEAR(g.SquaredMahalanobis(x), m2, kTol * (1 + m2));
      EXPECT_NEAR(g.ScaledDensity(x), std::exp(-0.5 * m2), kTol);
    }
    EXPECT_DOUBLE_EQ(g.ScaledDensity(g.mean()), 1.0);
    EXPECT_NEAR(g.log_det(), std::log(g.covariance().determinant()), kTol);
  }
}

TEST(GaussianTest, BatchLogDensityEqualsPointwise) {
  std::mt19937_64 rng(1);
  const Gaussian g(RandomVector(3, rng), RandomSpd(3, rng));
  Eigen::MatrixXd X(3, 7);
  for (int j = 0; j < 7; ++j) X.col(j) = RandomVector(3, rng);
  const Eigen::VectorXd batch = g.LogDensity(X);
  ASSERT_EQ(batch.size(), 7);
  for (int j = 0; j < 7; ++j) EXPECT_NEAR(batch[j], g.LogDensity(X.col(j)), kTol);
}

TEST(GaussianTest, LargeDimensionUsesHeapPath) {
  std::mt19937_64 rng(2);
  const int d = 40;  // above the stack buffer of SquaredMahalanobis
  const Gaussian g(RandomVector(d, rng), RandomSpd(d, rng));
  const Eigen::VectorXd x = RandomVector(d, rng);
  EXPECT_NEAR(g.LogDensity(x), NaiveLogDensity(x, g.mean(), g.covariance()), 1e-8);
}

TEST(GaussianTest, CreateRejectsNonPositiveDefinite) {
  Eigen::MatrixXd s(2, 2);
  s << 1, 2, 2, 1;  // eigenvalues 3 and -1
  EXPECT_FALSE(Gaussian::Create(Eigen::Vector2d(0, 0), s).has_value());
  Eigen::MatrixXd nan = Eigen::MatrixXd::Identity(2, 2);
  nan(0, 0) = std::nan("");
  EXPECT_FALSE(Gaussian::Create(Eigen::Vector2d(0, 0), nan).has_value());
  EXPECT_FALSE(Gaussian::Create(Eigen::Vector3d(0, 0, 0), Eigen::MatrixXd::Identity(2, 2)));

  Gaussian g(Eigen::Vector2d(1, 2), Eigen::MatrixXd::Identity(2, 2));
  EXPECT_FALSE(g.Set(Eigen::Vector2d(5, 5), s));
  EXPECT_EQ(g.mean(), Eigen::Vector2d(1, 2));  // old state kept
  EXPECT_FALSE(g.SetInPlace(Eigen::Vector2d(5, 5), s));
  EXPECT_EQ(g.mean(), Eigen::Vector2d(1, 2));
  EXPECT_EQ(g.cholesky_l(), Eigen::MatrixXd::Identity(2, 2));
}

TEST(GaussianTest, SetInPlaceEqualsSet) {
  std::mt19937_64 rng(3);
  const Eigen::VectorXd m = RandomVector(4, rng);
  const Eigen::MatrixXd s = RandomSpd(4, rng);
  Gaussian a(RandomVector(4, rng), RandomSpd(4, rng)), b = a;
  ASSERT_TRUE(a.Set(m, s));
  ASSERT_TRUE(b.SetInPlace(m, s));
  EXPECT_EQ(a.mean(), b.mean());
  EXPECT_EQ(a.covariance(), b.covariance());
  EXPECT_EQ(a.cholesky_l(), b.cholesky_l());
  EXPECT_EQ(a.log_det(), b.log_det());
}

// The O(d^2) update equals a fresh factorisation of alpha S + v v^T, for the unrolled sizes
// (d <= 12), the run-time-size loop and the refactorising path beyond the stack (d > 32); and
// stays consistent over a long chain of updates.
TEST(GaussianTest, ScaleAndRankOneUpdateEqualsRefactorisation) {
  std::mt19937_64 rng(11);
  for (int d : {1, 2, 5, 8, 12, 13, 20, 40}) {
    SCOPED_TRACE("d = " + std::to_string(d));
    const Eigen::MatrixXd s = RandomSpd(d, rng);
    Gaussian g(RandomVector(d, rng), s);
    const Eigen::VectorXd mean = RandomVector(d, rng), v = RandomVector(d, rng);
    const double alpha = 0.93;
    ASSERT_TRUE(g.ScaleAndRankOneUpdate(mean, alpha, v));
    const Gaussian want(mean, alpha * s + v * v.transpose());
    EXPECT_LE((g.cholesky_l() - want.cholesky_l()).norm(), kTol * want.cholesky_l().norm());
    EXPECT_LE((g.covariance() - want.covariance()).norm(), kTol * want.covariance().norm());
    EXPECT_EQ(g.covariance(), g.covariance().transpose());
    EXPECT_NEAR(g.log_det(), want.log_det(), kTol * std::max(1.0, std::abs(want.log_det())));
    const Eigen::VectorXd x = RandomVector(d, rng);
    EXPECT_NEAR(g.LogDensity(x), want.LogDensity(x), kTol * std::abs(want.LogDensity(x)));
  }
  for (int d : {3, 8}) {  // 2000 updates with the weights of a growing sample count
    Eigen::MatrixXd s = RandomSpd(d, rng);
    Gaussian g(Eigen::VectorXd::Zero(d), s);
    for (int n = 10; n < 2010; ++n) {
      const double alpha = n / (n + 1.0);
      const Eigen::VectorXd v = RandomVector(d, rng) / std::sqrt(n + 1.0);
      ASSERT_TRUE(g.ScaleAndRankOneUpdate(Eigen::VectorXd::Zero(d), alpha, v));
      s = alpha * s + v * v.transpose();
    }
    const Gaussian want(Eigen::VectorXd::Zero(d), s);
    EXPECT_LE((g.cholesky_l() - want.cholesky_l()).norm(), 1e-9 * want.cholesky_l().norm());
    EXPECT_NEAR(g.log_det(), want.log_det(), 1e-9 * std::max(1.0, std::abs(want.log_det())));
  }
}

// WhitenEach gives each Gaussian's L^-1 (x - mean) and m^2 (two at a time and the odd one alone,
// unrolled sizes, the run-time-size loop and the Eigen path beyond the stack).
TEST(GaussianTest, WhitenEachEqualsForwardSubstitution) {
  std::mt19937_64 rng(13);
  for (int d : {1, 3, 8, 13, 40}) {
    for (int k : {1, 2, 5}) {
      SCOPED_TRACE("d = " + std::to_string(d) + ", k = " + std::to_string(k));
      std::vector<Gaussian> gaussians;
      for (int i = 0; i < k; ++i) gaussians.emplace_back(RandomVector(d, rng), RandomSpd(d, rng));
      const Eigen::VectorXd x = RandomVector(d, rng);
      std::vector<double> z(static_cast<std::size_t>(k) * d), m2(k);
      Gaussian::WhitenEach(gaussians, x, z.data(), m2.data());
      for (int i = 0; i < k; ++i) {
        const Gaussian& g = gaussians[i];
        const Eigen::VectorXd want =
            g.cholesky_l().triangularView<Eigen::Lower>().solve(x - g.mean());
        const Eigen::Map<const Eigen::VectorXd> got(&z[static_cast<std::size_t>(i) * d], d);
        EXPECT_LE((got - want).norm(), kTol * (1 + want.norm()));
        EXPECT_NEAR(m2[i], g.SquaredMahalanobis(x), kTol * (1 + m2[i]));
      }
    }
  }
}

// covariance <- alpha covariance + rho v v^T, with L^-1 v given or not; covariance() of the updated
// Gaussian (rebuilt from the factor when read) and of its copies.
TEST(GaussianTest, ScaleAndRankOneUpdateWithWeightAndGivenSolve) {
  std::mt19937_64 rng(14);
  for (int d : {1, 4, 8, 12, 20, 40}) {
    SCOPED_TRACE("d = " + std::to_string(d));
    const Eigen::MatrixXd s = RandomSpd(d, rng);
    const Eigen::VectorXd mean = RandomVector(d, rng), v = RandomVector(d, rng);
    const double alpha = 0.97, rho = 0.3;
    const Gaussian want(mean, alpha * s + rho * v * v.transpose());
    Gaussian given(RandomVector(d, rng), s);
    Gaussian computed = given;
    const Eigen::VectorXd l_inv_v = given.cholesky_l().triangularView<Eigen::Lower>().solve(v);
    ASSERT_TRUE(given.ScaleAndRankOneUpdate(mean, alpha, v, rho, l_inv_v.data()));
    ASSERT_TRUE(computed.ScaleAndRankOneUpdate(mean, alpha, v, rho));
    for (const Gaussian* g : {&given, &computed}) {
      const Gaussian copy = *g;
      EXPECT_LE((g->cholesky_l() - want.cholesky_l()).norm(), kTol * want.cholesky_l().norm());
      EXPECT_NEAR(g->log_det(), want.log_det(), kTol * std::max(1.0, std::abs(want.log_det())));
      EXPECT_LE((copy.covariance() - want.covariance()).norm(), kTol * want.covariance().norm());
      EXPECT_EQ(g->covariance(), copy.covariance());
      EXPECT_EQ(g->covariance(), g->covariance().transpose());
      EXPECT_EQ(g->mean(), mean);
    }
  }
}

TEST(GaussianTest, ScaleAndRankOneUpdateRefusesBadInput) {
  std::mt19937_64 rng(12);
  Gaussian g(RandomVector(3, rng), RandomSpd(3, rng));
  const Gaussian before = g;
  const Eigen::VectorXd v = RandomVector(3, rng);
  EXPECT_FALSE(g.ScaleAndRankOneUpdate(g.mean(), 0.0, v));
  EXPECT_FALSE(g.ScaleAndRankOneUpdate(g.mean(), std::nan(""), v));
  Eigen::VectorXd bad = v;
  bad[1] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(g.ScaleAndRankOneUpdate(g.mean(), 0.5, bad));
  EXPECT_FALSE(g.ScaleAndRankOneUpdate(g.mean(), 0.5, v, -1.0));
  EXPECT_FALSE(g.ScaleAndRankOneUpdate(g.mean(), 0.5, v, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(g.covariance(), before.covariance());
  EXPECT_EQ(g.cholesky_l(), before.cholesky_l());
}

TEST(GaussianTest, MarginalTakesSubvectorAndSubmatrix) {
  std::mt19937_64 rng(4);
  const Gaussian g(RandomVector(4, rng), RandomSpd(4, rng));
  const Gaussian m = g.Marginal({3, 1});
  ASSERT_EQ(m.dim(), 2);
  EXPECT_EQ(m.mean()[0], g.mean()[3]);
  EXPECT_EQ(m.mean()[1], g.mean()[1]);
  EXPECT_EQ(m.covariance()(0, 0), g.covariance()(3, 3));
  EXPECT_EQ(m.covariance()(0, 1), g.covariance()(3, 1));
  EXPECT_EQ(m.covariance()(1, 1), g.covariance()(1, 1));
}

TEST(GaussianTest, ConditionalEqualsClosedForm) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const Gaussian g(RandomVector(5, rng), RandomSpd(5, rng));
    const std::vector<int> b = {4, 1};
    const std::vector<int> a = ComplementDims(5, b);
    ASSERT_EQ(a, (std::vector<int>{0, 2, 3}));
    const Eigen::VectorXd values = RandomVector(2, rng);
    const Gaussian c = g.Conditional(b, values);
    // Textbook: mu_a + S_ab S_bb^-1 (v - mu_b), S_aa - S_ab S_bb^-1 S_ba with explicit inverse.
    const Eigen::MatrixXd& s = g.covariance();
    Eigen::MatrixXd s_aa = s(a, a), s_ab = s(a, b), s_bb = s(b, b);
    const Eigen::VectorXd mu_a = g.mean()(a), mu_b = g.mean()(b);
    const Eigen::VectorXd mean = mu_a + s_ab * s_bb.inverse() * (values - mu_b);
    const Eigen::MatrixXd cov = s_aa - s_ab * s_bb.inverse() * s_ab.transpose();
    EXPECT_LE((c.mean() - mean).norm(), kTol);
    EXPECT_LE((c.covariance() - cov).norm(), kTol);
    // Chain rule: log N(x) = log N_b(x_b) + log N_{a|b}(x_a).
    Eigen::VectorXd x = RandomVector(5, rng);
    x(b) = values;
    EXPECT_NEAR(g.LogDensity(x), g.Marginal(b).LogDensity(values) + c.LogDensity(x(a)), kTol);
  }
}

TEST(GaussianTest, AffineMapsMeanAndCovariance) {
  std::mt19937_64 rng(6);
  const Gaussian g(RandomVector(3, rng), RandomSpd(3, rng));
  Eigen::MatrixXd A(2, 3);
  A << 1, 2, 0, 0, -1, 3;
  const Eigen::VectorXd b = Eigen::Vector2d(0.5, -1);
  const Gaussian y = g.Affine(A, b);
  EXPECT_LE((y.mean() - (A * g.mean() + b)).norm(), kTol);
  EXPECT_LE((y.covariance() - A * g.covariance() * A.transpose()).norm(), kTol);
}

TEST(GaussianTest, SampleMomentsMatch) {
  std::mt19937_64 rng(7);
  const Gaussian g(Eigen::Vector2d(1, -2), RandomSpd(2, rng));
  const int n = 20000;
  Eigen::MatrixXd X(2, n);
  for (int j = 0; j < n; ++j) X.col(j) = g.Sample(rng);
  const Eigen::VectorXd mean = X.rowwise().mean();
  const Eigen::MatrixXd centered = X.colwise() - mean;
  const Eigen::MatrixXd cov = centered * centered.transpose() / (n - 1);
  // Standard error of the mean is ~sigma / sqrt(n) ~ 0.01; 0.05 is five of them.
  EXPECT_LE((mean - g.mean()).norm(), 0.05);
  EXPECT_LE((cov - g.covariance()).norm(), 0.1);
}

TEST(GaussianTest, SameSeedSameSamples) {
  const Gaussian g(Eigen::Vector2d(0, 0), Eigen::MatrixXd::Identity(2, 2));
  std::mt19937_64 a(11), b(11);
  EXPECT_EQ(g.Sample(a), g.Sample(b));
}

}  // namespace
}  // namespace dgmm
