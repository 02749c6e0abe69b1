#include "core/dgmm.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core_test_utils.h"

namespace dgmm {
namespace {

using testing::ExpectDgmmInvariants;
using testing::RandomVector;

// Samples from a three-component mixture in d dimensions, means 4 apart.
Eigen::MatrixXd Stream(int d, int n, std::mt19937_64& rng) {
  Mixture source(d);
  for (int i = 0; i < 3; ++i) {
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(d);
    mean[i % d] = 4.0 * (i + 1);
    source.Add(1.0 + i, Gaussian(mean, Eigen::MatrixXd::Identity(d, d) * (0.5 + 0.25 * i)));
  }
  return source.Sample(n, rng);
}

// Version-1 behaviour (identity S0, blend covariance), which these tests were written for.
DgmmOptions PaperOptions() {
  DgmmOptions o;
  o.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;
  o.covariance_rule = DgmmOptions::CovarianceRule::kBlend;
  return o;
}

DgmmOptions Options(double k) {
  DgmmOptions o = PaperOptions();
  o.k = k;
  return o;
}

TEST(DgmmOptionsTest, IsValid) {
  std::string error;
  EXPECT_TRUE(DgmmOptions{}.IsValid(&error));
  // The default S0 follows the data: unresolved, it is not valid for a model.
  EXPECT_FALSE(DgmmOptions{}.IsValid(2, &error));
  EXPECT_NE(error.find("resolved"), std::string::npos);
  EXPECT_TRUE(PaperOptions().IsValid(2, &error));
  for (double k : {0.0, -1.0, std::nan(""), double{INFINITY}}) {
    EXPECT_FALSE(Options(k).IsValid(&error)) << k;
    EXPECT_NE(error.find("k must be"), std::string::npos);
  }
  DgmmOptions o = PaperOptions();
  o.covariance_floor = -1;
  EXPECT_FALSE(o.IsValid(&error));
  o = PaperOptions();
  o.initial_covariance_diagonal = Eigen::Vector2d(1, 0);
  EXPECT_FALSE(o.IsValid(&error));
  o.initial_covariance_diagonal = Eigen::Vector2d(1, 2);
  EXPECT_TRUE(o.IsValid(&error));
  EXPECT_TRUE(o.IsValid(2, &error));
  EXPECT_FALSE(o.IsValid(3, &error));
  EXPECT_NE(error.find("3 dimensions"), std::string::npos);
}

TEST(DgmmTest, FirstSampleStartsAComponentWithInitialCovariance) {
  DgmmOptions o = PaperOptions();
  o.initial_covariance_diagonal = Eigen::Vector2d(0.5, 2.0);
  o.covariance_floor = 0;
  Dgmm model(2, o);
  std::mt19937_64 rng(0);
  const AddSampleResult r = model.AddSample(Eigen::Vector2d(1, 2), rng);
  EXPECT_FALSE(r.merged);
  EXPECT_EQ(r.component, 0);
  ASSERT_EQ(model.mixture().size(), 1);
  EXPECT_EQ(model.mixture().weight(0), 1.0);
  EXPECT_EQ(model.mixture().component(0).mean(), Eigen::Vector2d(1, 2));
  EXPECT_EQ(model.mixture().component(0).covariance(),
            Eigen::Vector2d(0.5, 2.0).asDiagonal().toDenseMatrix());
}

// Per component: the samples it received, and the paper's eqs. 11-13 coded literally:
// w' = w + 1, mu' = mu + (x - mu) / w', S' = (w - 1)/w S + (x - mu)(x - mu)^T / w'.
struct Received {
  std::vector<Eigen::VectorXd> samples;
  double w = 0;
  Eigen::VectorXd mu;
  Eigen::MatrixXd s;
};

TEST(DgmmTest, IncrementalUpdateEqualsBatchAndPaperRecursion) {
  for (int d : {1, 3, 6}) {
    std::mt19937_64 data_rng(d), rng(100 + d);
    const Eigen::MatrixXd X = Stream(d, 2000, data_rng);
    Dgmm model(d, Options(0.05));
    std::map<int, Received> received;
    for (int j = 0; j < X.cols(); ++j) {
      const Eigen::VectorXd x = X.col(j);
      const AddSampleResult r = model.AddSample(x, rng);
      Received& rec = received[r.component];
      rec.samples.push_back(x);
      if (rec.w == 0) {
        rec.w = 1;
        rec.mu = x;
        rec.s = Eigen::MatrixXd::Zero(d, d);  // S of one sample: 0 (its (w-1)/w factor is 0)
      } else {
        const Eigen::VectorXd delta = x - rec.mu;
        const double w = rec.w;
        rec.w = w + 1;
        rec.mu = rec.mu + delta / rec.w;
        rec.s = (w - 1) / w * rec.s + delta * delta.transpose() / rec.w;
      }
    }
    ASSERT_EQ(static_cast<int>(received.size()), model.mixture().size());
    int checked = 0;
    for (const auto& [i, rec] : received) {
      SCOPED_TRACE("d=" + std::to_string(d) + " component " + std::to_string(i));
      const DgmmComponentStats& s = model.stats()[i];
      const int n = static_cast<int>(rec.samples.size());
      ASSERT_EQ(s.count, n);
      EXPECT_EQ(model.mixture().weight(i), rec.w);
      Eigen::VectorXd mean = Eigen::VectorXd::Zero(d);
      for (const auto& x : rec.samples) mean += x;
      mean /= n;
      // Relative 1e-10 as required; both sides carry O(n eps) round-off.
      EXPECT_LE((s.mean - mean).norm(), 1e-10 * (1 + mean.norm()));
      EXPECT_LE((s.mean - rec.mu).norm(), 1e-10 * (1 + mean.norm()));
      if (n < 2) continue;
      Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(d, d);
      for (const auto& x : rec.samples) cov += (x - mean) * (x - mean).transpose();
      cov /= (n - 1);  // unbiased
      const Eigen::MatrixXd inc = model.SampleCovariance(i);
      EXPECT_LE((inc - cov).norm(), 1e-10 * cov.norm());
      EXPECT_LE((inc - rec.s).norm(), 1e-10 * cov.norm());
      ++checked;
    }
    EXPECT_GE(checked, 1);
  }
}

// Algorithm 2 without the shortcut, evaluated on a copy of the generator before each call:
// the implementation (which skips d when r < 1 - exp(-k n)) must take the same decisions. Draws
// whose outcome is certain are not made: r once 1 - exp(-k n) rounds to 1 (every r in [0, 1)
// merges), and the component draw when there is one component.
TEST(DgmmTest, MatchesLiteralAlgorithm2) {
  for (double k : {0.01, 0.2, 0.7}) {
    std::mt19937_64 data_rng(7), rng(8);
    const Eigen::MatrixXd X = Stream(2, 200, data_rng);
    Dgmm model(2, Options(k));
    int evaluated = 0, merged = 0, started = 0;
    for (int j = 0; j < X.cols(); ++j) {
      const Eigen::VectorXd x = X.col(j);
      std::mt19937_64 ref_rng = rng;
      std::uniform_real_distribution<double> uniform(0.0, 1.0);
      const Mixture& m = model.mixture();
      const double n = static_cast<double>(model.num_samples());
      const bool certain = !m.empty() && 1.0 - std::exp(-k * n) == 1.0;
      const double r = certain ? 0.0 : uniform(ref_rng);
      double d = 0;
      if (!m.empty()) d = std::exp(m.LogDensity(x) - m.MaxDensity().log_density);
      const double t = 1 - (1 - std::min(d, 1.0)) * std::exp(-k * n);
      const bool expect_merge = r < t;
      int expect_component = m.size();
      if (expect_merge) {
        std::vector<double> p(m.size());
        double total = 0;
        for (int i = 0; i < m.size(); ++i) {
          p[i] = m.weight(i) * m.component(i).ScaledDensity(x);
          total += p[i];
        }
        const double u = m.size() == 1 ? 0.0 : uniform(ref_rng) * total;
        double c = 0;
        for (expect_component = 0; expect_component < m.size(); ++expect_component) {
          c += p[expect_component];
          if (u < c) break;
        }
      }
      const AddSampleResult result = model.AddSample(x, rng);
      ASSERT_EQ(result.merged, expect_merge) << "sample " << j;
      ASSERT_EQ(result.component, expect_component) << "sample " << j;
      if (result.density_evaluated) {
        EXPECT_NEAR(result.threshold, t, 1e-9);
        ++evaluated;
      } else if (result.merged) {  // a lower bound on t proved r < t
        EXPECT_LE(result.threshold, t + 1e-12);
        EXPECT_LT(r, result.threshold);
      } else {  // an upper bound on t proved r >= t
        EXPECT_GE(result.threshold, t - 1e-12);
        EXPECT_LE(result.threshold, r);
      }
      (result.merged ? merged : started)++;
      EXPECT_EQ(rng, ref_rng);  // same number of draws
    }
    EXPECT_GT(merged, 0);
    EXPECT_GT(started, 1);
  }
}

TEST(DgmmTest, InvariantsHoldOverManySeededStreams) {
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    const int d = 1 + static_cast<int>(seed % 8);
    std::uniform_real_distribution<double> log_k(std::log(1e-2), std::log(5.0));
    const double k = std::exp(log_k(rng));
    const Eigen::MatrixXd X = Stream(d, 100 + 10 * static_cast<int>(seed), rng);
    Dgmm model(d, Options(k));
    for (int j = 0; j < X.cols(); ++j) model.AddSample(X.col(j), rng);
    EXPECT_EQ(model.num_samples(), X.cols());
    ExpectDgmmInvariants(model);
  }
}

// Merges update each component's factor by rank-one steps (O(d^2)); the covariance it holds
// must stay the options' rule applied to the statistics, up to the floor's documented sag (under
// 1% of the floor between factorisations), for every rule, and the factor must match it.
TEST(DgmmTest, RankOneUpdatesTrackTheCovarianceRule) {
  using Rule = DgmmOptions::CovarianceRule;
  for (Rule rule : {Rule::kPrior, Rule::kLiteral, Rule::kBlend}) {
    for (double floor : {1e-3, 0.0}) {
      SCOPED_TRACE(std::string(CovarianceRuleName(rule)) + " floor " + std::to_string(floor));
      std::mt19937_64 data_rng(3), rng(4);
      const int d = 6;
      const Eigen::MatrixXd X = Stream(d, 5000, data_rng);
      DgmmOptions o = PaperOptions();
      o.covariance_rule = rule;
      o.covariance_floor = floor;
      o.covariance_floor_relative = 0.0;
      Dgmm model(d, o);
      for (int j = 0; j < X.cols(); ++j) model.AddSample(X.col(j), rng);
      ExpectDgmmInvariants(model);
      for (int i = 0; i < model.mixture().size(); ++i) {
        const Gaussian& g = model.mixture().component(i);
        const Eigen::MatrixXd want = model.FlooredCovariance(model.stats()[i]);
        const Eigen::MatrixXd diff = g.covariance() - want;
        EXPECT_LE(diff.norm(), 0.01 * floor * std::sqrt(d) + 1e-10 * want.norm());
        if (floor > 0) EXPECT_LE(diff.diagonal().maxCoeff(), 1e-10 * want.norm());
        const Eigen::MatrixXd llt = g.cholesky_l() * g.cholesky_l().transpose();
        EXPECT_LE((llt - g.covariance()).norm(), 1e-10 * want.norm());
      }
    }
  }
}

TEST(DgmmTest, DegenerateSamplesStayPositiveDefinite) {
  // Repeated identical samples and samples on a line give singular sample covariances.
  for (double floor : {1e-6, 0.0}) {
    DgmmOptions o = PaperOptions();
    o.covariance_floor = floor;
    Dgmm model(3, o);
    std::mt19937_64 rng(1);
    for (int j = 0; j < 200; ++j) model.AddSample(Eigen::Vector3d(1, 2, 3), rng);
    for (int j = 0; j < 200; ++j) model.AddSample(Eigen::Vector3d(j * 0.01, 0, 0), rng);
    ExpectDgmmInvariants(model);
  }
}

TEST(DgmmTest, FlooredCovarianceBlendsTowardInitialUntilFullRank) {
  DgmmOptions o = PaperOptions();
  o.covariance_floor = 1e-3;
  o.initial_covariance_diagonal = Eigen::Vector2d(4, 9);
  const Dgmm model(2, o);
  DgmmComponentStats s;
  s.count = 1;
  s.mean = Eigen::Vector2d(0, 0);
  s.scatter = Eigen::MatrixXd::Zero(2, 2);
  const Eigen::MatrixXd s0 = Eigen::Vector2d(4, 9).asDiagonal();
  const Eigen::MatrixXd floor = 1e-3 * Eigen::MatrixXd::Identity(2, 2);
  EXPECT_LE((model.FlooredCovariance(s) - (s0 + floor)).norm(), 1e-15);
  s.count = 2;
  s.scatter << 2, 1, 1, 2;
  EXPECT_LE((model.FlooredCovariance(s) - ((s.scatter + s0) / 2 + floor)).norm(), 1e-15);
  s.count = 10;  // > dim: the unbiased sample covariance plus the floor
  EXPECT_LE((model.FlooredCovariance(s) - (s.scatter / 9 + floor)).norm(), 1e-15);
}

Dgmm Learn(std::uint64_t seed, double k, const Eigen::MatrixXd& X) {
  Dgmm model(static_cast<int>(X.rows()), Options(k));
  std::mt19937_64 rng(seed);
  for (int j = 0; j < X.cols(); ++j) model.AddSample(X.col(j), rng);
  return model;
}

TEST(DgmmTest, SameSeedSameModelDifferentSeedDifferentModel) {
  std::mt19937_64 data_rng(3);
  const Eigen::MatrixXd X = Stream(3, 500, data_rng);
  const Dgmm a = Learn(1, 0.05, X), b = Learn(1, 0.05, X), c = Learn(2, 0.05, X);
  ASSERT_EQ(a.mixture().size(), b.mixture().size());
  for (int i = 0; i < a.mixture().size(); ++i) {
    EXPECT_EQ(a.mixture().weight(i), b.mixture().weight(i));
    EXPECT_EQ(a.mixture().component(i).mean(), b.mixture().component(i).mean());
    EXPECT_EQ(a.mixture().component(i).covariance(), b.mixture().component(i).covariance());
  }
  bool differs = a.mixture().size() != c.mixture().size();
  for (int i = 0; !differs && i < a.mixture().size(); ++i) {
    differs = a.mixture().weight(i) != c.mixture().weight(i);
  }
  EXPECT_TRUE(differs);
}

TEST(DgmmTest, LargeKGivesOneComponentTinyKGivesMany) {
  std::mt19937_64 data_rng(4);
  // Widely spread points relative to the unit initial covariance.
  Eigen::MatrixXd X(2, 150);
  std::uniform_real_distribution<double> u(-100, 100);
  for (int i = 0; i < X.size(); ++i) X.data()[i] = u(data_rng);
  EXPECT_EQ(Learn(5, 1e3, X).mixture().size(), 1);
  EXPECT_GT(Learn(5, 1e-9, X).mixture().size(), 50);
}

TEST(DgmmTest, ImprovedVariantKeepsInvariants) {
  DgmmOptions o = PaperOptions();
  o.variant = DgmmOptions::Variant::kImproved;
  Dgmm model(2, o);
  std::mt19937_64 rng(6);
  const Eigen::MatrixXd X = Stream(2, 300, rng);
  for (int j = 0; j < X.cols(); ++j) model.AddSample(X.col(j), rng);
  EXPECT_EQ(model.num_samples(), 300);
  testing::ExpectMixtureInvariants(model.mixture());
}

}  // namespace
}  // namespace dgmm
