#include <gtest/gtest.h>

#include <random>

#include "core/dgmm.h"
#include "core/mise.h"

namespace dgmm {
namespace {

// Identity S0 (these tests use standardised-scale data) and each variant's version-1 covariance:
// the blend for the paper's, one S0 pseudo-sample (the prior rule, nu0 = 1) for the improved.
DgmmOptions Options(DgmmOptions::Variant variant, double k) {
  DgmmOptions o;
  o.variant = variant;
  o.k = k;
  o.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;
  o.covariance_rule = variant == DgmmOptions::Variant::kImproved
                          ? DgmmOptions::CovarianceRule::kPrior
                          : DgmmOptions::CovarianceRule::kBlend;
  o.prior_pseudo_count = 1.0;
  return o;
}
DgmmOptions Improved(double k) { return Options(DgmmOptions::Variant::kImproved, k); }

// Invariants of any ADDSAMPLE: weights are sample counts summing to n, covariances factor.
TEST(DgmmImprovedTest, WeightsCountSamplesAndCovariancesStayPositiveDefinite) {
  for (std::uint64_t seed = 0; seed < 5; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    Dgmm model(3, Improved(0.7));
    for (int i = 0; i < 300; ++i) {
      Eigen::Vector3d x(n(rng), n(rng) + (i % 2) * 4, n(rng));
      model.AddSample(x, rng);
    }
    EXPECT_EQ(model.num_samples(), 300);
    EXPECT_NEAR(model.mixture().total_weight(), 300.0, 1e-9);
    for (int i = 0; i < model.mixture().size(); ++i) {
      EXPECT_EQ(model.mixture().weight(i), model.stats()[i].count);
      Eigen::LLT<Eigen::MatrixXd> llt(model.mixture().component(i).covariance());
      EXPECT_EQ(llt.info(), Eigen::Success);
    }
  }
}

// With k huge every sample after the first merges into the one component: its statistics must be
// the recency-weighted mean and covariance (weights 1..n) in closed form.
TEST(DgmmImprovedTest, OneComponentHoldsRecencyWeightedStatistics) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  const int count = 40;
  Eigen::MatrixXd xs(2, count);
  for (int i = 0; i < count; ++i) xs.col(i) = Eigen::Vector2d(n(rng) + 0.05 * i, 2 * n(rng));
  Dgmm model(2, Improved(1e6));
  for (int i = 0; i < count; ++i) model.AddSample(xs.col(i), rng);
  ASSERT_EQ(model.mixture().size(), 1);
  double w = 0, s2 = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (int i = 0; i < count; ++i) w += i + 1, s2 += (i + 1.0) * (i + 1.0), mean += (i + 1) * xs.col(i);
  mean /= w;
  Eigen::Matrix2d m2 = Eigen::Matrix2d::Zero();
  for (int i = 0; i < count; ++i) m2 += (i + 1) * (xs.col(i) - mean) * (xs.col(i) - mean).transpose();
  const Eigen::Matrix2d weighted_cov = m2 / (w - s2 / w);
  // The prior rule (nu0 = 1, S0 = I) on the weighted scatter (n - 1) C_w.
  const Eigen::Matrix2d expected =
      ((count - 1) * weighted_cov + Eigen::Matrix2d::Identity()) / (count + 1.0) +
      model.options().covariance_floor * Eigen::Matrix2d::Identity();
  const double kRel = 1e-10;  // round-off of 40 incremental updates
  EXPECT_LT((model.stats()[0].mean - mean).norm(), kRel * (1 + mean.norm()));
  EXPECT_LT((model.SampleCovariance(0) - weighted_cov).norm(), kRel * weighted_cov.norm());
  EXPECT_LT((model.mixture().component(0).covariance() - expected).norm(), kRel * expected.norm());
}

// A merged sample goes to the component with the highest normalised density N_i(x).
TEST(DgmmImprovedTest, MergesIntoTheMostLikelyComponent) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  Dgmm model(2, Improved(0.05));
  int merges = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector2d x(n(rng) + 6.0 * (i % 3), 0.5 * n(rng));
    int expected = -1;
    double best = -1e300;
    for (int c = 0; c < model.mixture().size(); ++c) {
      const double l = model.mixture().component(c).LogDensity(x);
      if (l > best) best = l, expected = c;
    }
    const AddSampleResult r = model.AddSample(x, rng);
    if (r.merged) {
      ++merges;
      EXPECT_EQ(r.component, expected);
    }
  }
  EXPECT_GT(merges, 300);
}

TEST(DgmmImprovedTest, SameSeedSameModel) {
  auto fit = [](std::uint64_t seed) {
    std::mt19937_64 data(11), rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    Dgmm model(2, Improved(0.3));
    for (int i = 0; i < 200; ++i) model.AddSample(Eigen::Vector2d(n(data), n(data) * 3), rng);
    return model.mixture();
  };
  const Mixture a = fit(7), b = fit(7);
  ASSERT_EQ(a.size(), b.size());
  for (int i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.weight(i), b.weight(i));
    EXPECT_EQ(a.component(i).mean(), b.component(i).mean());
  }
}

// Two separated clusters (Old Faithful-like, standardised): among single passes that end with two
// Gaussians, the improved variant is closer to the truth than the paper's on average.
TEST(DgmmImprovedTest, CloserToTheTruthThanFaithfulOnTwoClusters) {
  Mixture truth(2);
  Eigen::Matrix2d ca, cb;
  ca << 0.08, 0.03, 0.03, 0.12;
  cb << 0.15, 0.05, 0.05, 0.2;
  truth.Add(0.35, Gaussian(Eigen::Vector2d(-1.3, -1.2), ca));
  truth.Add(0.65, Gaussian(Eigen::Vector2d(0.7, 0.65), cb));
  auto mean_ise = [&](DgmmOptions::Variant variant) {
    double total = 0;
    int runs = 0;
    for (std::uint64_t seed = 0; seed < 200 && runs < 25; ++seed) {
      std::mt19937_64 rng(seed);
      const Eigen::MatrixXd xs = truth.Sample(272, rng);
      Dgmm model(2, Options(variant, 0.7));
      for (int i = 0; i < xs.cols(); ++i) model.AddSample(xs.col(i), rng);
      if (model.mixture().size() != 2) continue;
      total += IntegratedSquaredError(model.mixture(), truth);
      ++runs;
    }
    EXPECT_GE(runs, 10);
    return total / runs;
  };
  EXPECT_LT(mean_ise(DgmmOptions::Variant::kImproved),
            0.5 * mean_ise(DgmmOptions::Variant::kFaithful));
}

}  // namespace
}  // namespace dgmm
