#include "em/em.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "util/error.h"

namespace dgmm {
namespace {

// Rounding in sums over a few hundred samples: far below any EM step worth checking.
constexpr double kRoundoff = 1e-9;

// n samples from each of `means` (rows) with covariance scale^2 * A A^T for a random A; rows
// grouped by component.
Eigen::MatrixXd SampleMixture(const Eigen::MatrixXd& means, int n, double scale,
                              std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const Eigen::Index K = means.rows(), d = means.cols();
  Eigen::MatrixXd X(K * n, d);
  for (Eigen::Index k = 0; k < K; ++k) {
    Eigen::MatrixXd A(d, d);
    for (Eigen::Index a = 0; a < d * d; ++a) A.data()[a] = normal(rng);
    A = scale * (A + 2.0 * Eigen::MatrixXd::Identity(d, d));
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd e(d);
      for (Eigen::Index j = 0; j < d; ++j) e(j) = normal(rng);
      X.row(k * n + i) = (means.row(k).transpose() + A * e).transpose();
    }
  }
  return X;
}

TEST(EmOptionsTest, RejectsEveryInvalidField) {
  std::string error;
  EXPECT_TRUE(EmOptions{}.IsValid(&error));
  EXPECT_TRUE(error.empty());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<EmOptions> bad(9);
  bad[0].components = 0;
  bad[1].components = -3;
  bad[2].n_init = 0;
  bad[3].max_iterations = -1;
  bad[4].tolerance = -1e-3;
  bad[5].tolerance = nan;
  bad[6].reg_covar = -1e-6;
  bad[7].reg_covar = inf;
  bad[8].reg_covar = nan;
  for (const EmOptions& o : bad) {
    EXPECT_FALSE(o.IsValid(&error));
    EXPECT_FALSE(error.empty());
    EXPECT_THROW(FitEm(Eigen::MatrixXd::Random(10, 2), o), InputError);
  }
}

TEST(EmTest, BadSamplesThrowInputError) {
  EmOptions o;
  o.components = 3;
  EXPECT_THROW(FitEm(Eigen::MatrixXd::Random(2, 2), o), InputError);  // n < components
  EXPECT_THROW(FitEm(Eigen::MatrixXd(0, 2), o), InputError);
  Eigen::MatrixXd X = Eigen::MatrixXd::Random(20, 2);
  X(4, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(FitEm(X, o), InputError);
  X(4, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(FitEm(X, o), InputError);
}

TEST(EmTest, OneComponentIsSampleMeanAndMaximumLikelihoodCovariance) {
  // d = 1..8 run the fixed-size kernels, d = 11 the generic code.
  for (int d : {1, 2, 3, 6, 8, 11}) {
    const Eigen::MatrixXd means = Eigen::RowVectorXd::LinSpaced(d, -2.0, 3.0);
    const Eigen::MatrixXd X = SampleMixture(means, 201, 0.7, 5 + d);
    EmOptions o;
    o.components = 1;
    o.reg_covar = 1e-3;
    const EmResult r = FitEm(X, o);
    ASSERT_FALSE(r.summary.failed);
    ASSERT_EQ(r.mixture.size(), 1);
    const Eigen::RowVectorXd mean = X.colwise().mean();
    const Eigen::MatrixXd centred = X.rowwise() - mean;
    Eigen::MatrixXd cov = centred.transpose() * centred / X.rows();  // biased (ML)
    cov.diagonal().array() += o.reg_covar;
    EXPECT_LT((r.mixture.component(0).mean() - mean.transpose()).norm(), 1e-10 * mean.norm())
        << "d = " << d;
    EXPECT_LT((r.mixture.component(0).covariance() - cov).norm(), 1e-10 * cov.norm())
        << "d = " << d;
    EXPECT_NEAR(r.mixture.weight(0), X.rows(), 1e-9);
    // One component: the log-likelihood is the Gaussian's, reached after one M-step.
    const double expected = r.mixture.component(0).LogDensity(Eigen::MatrixXd(X.transpose())).sum();
    EXPECT_NEAR(r.summary.log_likelihood, expected, kRoundoff * std::abs(expected));
  }
}

TEST(EmTest, LogLikelihoodNeverDecreasesOverManySeededCases) {
  for (std::uint64_t seed = 0; seed < 24; ++seed) {
    std::mt19937_64 rng(seed);
    // d = 1..5, and 10 (the generic code beyond the fixed-size kernels) for every sixth seed.
    const int d = seed % 6 == 5 ? 9 + static_cast<int>(seed % 2) : 1 + static_cast<int>(seed % 5);
    const int K = 1 + static_cast<int>(seed % 4);
    // Overlapping clusters so EM takes many small steps.
    const Eigen::MatrixXd means = 2.0 * Eigen::MatrixXd::Random(K + 1, d);
    const Eigen::MatrixXd X = SampleMixture(means, 40, 1.0, seed);
    EmOptions o;
    o.components = K;
    o.tolerance = 0;
    o.max_iterations = 60;
    o.seed = seed;
    const EmResult r = FitEm(X, o);
    ASSERT_FALSE(r.summary.failed) << "seed " << seed;
    ASSERT_EQ(static_cast<int>(r.summary.history.size()), r.summary.iterations + 1);
    for (size_t t = 1; t < r.summary.history.size(); ++t) {
      const double previous = r.summary.history[t - 1];
      EXPECT_GE(r.summary.history[t], previous - kRoundoff * std::abs(previous))
          << "seed " << seed << " iteration " << t;
    }
    double total_weight = 0;
    for (int k = 0; k < r.mixture.size(); ++k) total_weight += r.mixture.weight(k);
    EXPECT_NEAR(total_weight, X.rows(), 1e-9 * X.rows());
  }
}

TEST(EmTest, SummaryLogLikelihoodIsTheMixtureDensity) {
  Eigen::MatrixXd means(2, 2);
  means << 0, 0, 4, 1;
  const Eigen::MatrixXd X = SampleMixture(means, 150, 0.5, 9);
  EmOptions o;
  o.n_init = 3;
  const EmResult r = FitEm(X, o);
  const double total = r.mixture.LogDensity(Eigen::MatrixXd(X.transpose())).sum();
  EXPECT_NEAR(r.summary.log_likelihood, total, kRoundoff * std::abs(total));
  EXPECT_NEAR(r.summary.mean_log_likelihood * X.rows(), total, kRoundoff * std::abs(total));
  EXPECT_EQ(r.summary.history.back(), r.summary.mean_log_likelihood);
  EXPECT_EQ(r.summary.samples, X.rows());
  EXPECT_EQ(r.summary.restarts, 3);
}

TEST(EmTest, RecoversWellSeparatedClusters) {
  Eigen::MatrixXd means(3, 2);
  means << 0, 0, 20, 0, 0, 20;
  const Eigen::MatrixXd X = SampleMixture(means, 100, 0.5, 2);
  EmOptions o;
  o.components = 3;
  o.n_init = 2;
  const EmResult r = FitEm(X, o);
  ASSERT_EQ(r.mixture.size(), 3);
  EXPECT_TRUE(r.summary.converged);
  EXPECT_LT(r.summary.iterations, o.max_iterations);
  for (int c = 0; c < 3; ++c) {
    // The fitted component nearest to each true mean carries its 100 samples.
    int nearest = 0;
    for (int k = 1; k < 3; ++k) {
      if ((r.mixture.component(k).mean() - means.row(c).transpose()).norm() <
          (r.mixture.component(nearest).mean() - means.row(c).transpose()).norm())
        nearest = k;
    }
    const Eigen::RowVectorXd sample_mean = X.middleRows(c * 100, 100).colwise().mean();
    EXPECT_LT((r.mixture.component(nearest).mean() - sample_mean.transpose()).norm(), 1e-6);
    EXPECT_NEAR(r.mixture.weight(nearest), 100.0, 1e-6);
  }
}

TEST(EmTest, SameSeedSameResultAndMoreRestartsNeverWorse) {
  Eigen::MatrixXd means(3, 3);
  means << 0, 0, 0, 2, 1, 0, 0, 2, 2;
  const Eigen::MatrixXd X = SampleMixture(means, 60, 0.8, 4);
  EmOptions o;
  o.components = 3;
  o.seed = 42;
  const EmResult a = FitEm(X, o), b = FitEm(X, o);
  EXPECT_EQ(a.summary.log_likelihood, b.summary.log_likelihood);
  EXPECT_EQ(a.summary.history, b.summary.history);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.mixture.weight(k), b.mixture.weight(k));
    EXPECT_EQ(a.mixture.component(k).mean(), b.mixture.component(k).mean());
    EXPECT_EQ(a.mixture.component(k).covariance(), b.mixture.component(k).covariance());
  }
  // The first restart draws the same numbers, so the best of five is at least as good.
  o.n_init = 5;
  EXPECT_GE(FitEm(X, o).summary.log_likelihood, a.summary.log_likelihood);
}

TEST(EmTest, BicIsMinusTwiceLogLikelihoodPlusParametersTimesLogN) {
  EXPECT_EQ(MixtureParameterCount(1, 1), 2);   // mean, variance
  EXPECT_EQ(MixtureParameterCount(2, 2), 11);  // 1 weight, 4 means, 6 covariance entries
  EXPECT_EQ(MixtureParameterCount(3, 6), 83);  // 2 + 18 + 63
  const Eigen::MatrixXd X = SampleMixture(Eigen::MatrixXd::Random(2, 2) * 3, 80, 0.5, 8);
  const EmResult r = FitEm(X, EmOptions{});
  EXPECT_NEAR(r.summary.bic, -2 * r.summary.log_likelihood + 11 * std::log(160.0), 1e-9);
  EXPECT_NEAR(BayesianInformationCriterion(-100, 50, 2, 2), 200 + 11 * std::log(50.0), 1e-12);
}

TEST(EmTest, ZeroIterationsReturnsTheKMeansInitialisation) {
  const Eigen::MatrixXd X = SampleMixture(Eigen::MatrixXd::Random(2, 2) * 5, 30, 0.5, 1);
  EmOptions o;
  o.max_iterations = 0;
  const EmResult r = FitEm(X, o);
  EXPECT_EQ(r.summary.iterations, 0);
  EXPECT_FALSE(r.summary.converged);
  ASSERT_EQ(r.summary.history.size(), 1u);
  EXPECT_TRUE(std::isfinite(r.summary.mean_log_likelihood));
}

TEST(EmTest, DuplicatePointsNeedRegularisation) {
  Eigen::MatrixXd X = Eigen::MatrixXd::Ones(12, 3);
  EmOptions o;
  o.n_init = 2;
  const EmResult regularised = FitEm(X, o);
  ASSERT_FALSE(regularised.summary.failed);
  EXPECT_TRUE(std::isfinite(regularised.summary.log_likelihood));
  o.reg_covar = 0;
  const EmResult singular = FitEm(X, o);
  EXPECT_TRUE(singular.summary.failed);
  EXPECT_EQ(singular.summary.failed_restarts, 2);
  EXPECT_TRUE(singular.mixture.empty());
  EXPECT_NE(singular.summary.BriefReport().find("failed"), std::string::npos);
}

}  // namespace
}  // namespace dgmm
