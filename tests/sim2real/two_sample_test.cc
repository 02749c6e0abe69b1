// MMD permutation test and Benjamini-Hochberg against closed forms and known cases.
#include "sim2real/two_sample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace dgmm::sim2real {
namespace {

Eigen::MatrixXd Normal(int n, int d, double shift, std::mt19937_64& rng) {
  std::normal_distribution<double> z(0.0, 1.0);
  Eigen::MatrixXd m(n, d);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < d; ++j) m(i, j) = z(rng) + (j == 0 ? shift : 0.0);
  return m;
}

TEST(BenjaminiHochberg, MatchesTheStepUpFormula) {
  // p sorted: 0.01, 0.02, 0.03, 0.5 (m = 4): q_(i) = min_{j >= i} p_(j) m / j.
  std::vector<double> q = BenjaminiHochberg({0.03, 0.01, 0.5, 0.02});
  EXPECT_NEAR(q[1], 0.04, 1e-12);  // min(0.04, 0.04, 0.04, 0.5)
  EXPECT_NEAR(q[3], 0.04, 1e-12);
  EXPECT_NEAR(q[0], 0.04, 1e-12);
  EXPECT_NEAR(q[2], 0.5, 1e-12);
}

TEST(MmdTest, SameDistributionIsRarelyRejected) {
  std::mt19937_64 rng(0);
  int rejected = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    MmdResult r = MmdTest(Normal(30, 3, 0, rng), Normal(40, 3, 0, rng), MmdOptions{200}, rng);
    rejected += r.p_value < 0.05;
  }
  // Expected 2 of 40 at level 0.05; 8 would be a p < 0.001 event for a valid test.
  EXPECT_LE(rejected, 8);
}

TEST(MmdTest, ShiftedDistributionIsRejected) {
  std::mt19937_64 rng(1);
  MmdResult r = MmdTest(Normal(40, 3, 1.0, rng), Normal(60, 3, 0, rng), MmdOptions{500}, rng);
  EXPECT_LT(r.p_value, 0.01);
  EXPECT_GT(r.mmd2, 0);
}

TEST(MmdTest, TooFewSamplesGiveNoEvidence) {
  std::mt19937_64 rng(2);
  EXPECT_EQ(MmdTest(Normal(1, 2, 5, rng), Normal(10, 2, 0, rng), MmdOptions{}, rng).p_value, 1.0);
}

// The unbiased MMD^2 written out pair by pair (Gretton et al. 2012, eq. 3) with the median-heuristic
// bandwidth over the pooled rows.
double Mmd2ByPairs(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd pooled(a.rows() + b.rows(), a.cols());
  pooled << a, b;
  std::vector<double> d2;
  for (int i = 0; i < pooled.rows(); ++i)
    for (int j = i + 1; j < pooled.rows(); ++j) d2.push_back((pooled.row(i) - pooled.row(j)).squaredNorm());
  std::nth_element(d2.begin(), d2.begin() + d2.size() / 2, d2.end());
  const double h2 = d2[d2.size() / 2];
  auto k = [&](const Eigen::MatrixXd& x, int i, const Eigen::MatrixXd& y, int j) {
    return std::exp(-(x.row(i) - y.row(j)).squaredNorm() / (2 * h2));
  };
  const double na = a.rows(), nb = b.rows();
  double saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < na; ++i)
    for (int j = 0; j < na; ++j) saa += i == j ? 0.0 : k(a, i, a, j);
  for (int i = 0; i < nb; ++i)
    for (int j = 0; j < nb; ++j) sbb += i == j ? 0.0 : k(b, i, b, j);
  for (int i = 0; i < na; ++i)
    for (int j = 0; j < nb; ++j) sab += k(a, i, b, j);
  return saa / (na * (na - 1)) + sbb / (nb * (nb - 1)) - 2 * sab / (na * nb);
}

TEST(MmdTest, TheStatisticIsTheUnbiasedEstimate) {
  std::mt19937_64 rng(7);
  for (const double shift : {0.0, 0.7}) {
    const Eigen::MatrixXd a = Normal(23, 3, shift, rng), b = Normal(31, 3, 0, rng);
    EXPECT_NEAR(MmdTest(a, b, MmdOptions{10}, rng).mmd2, Mmd2ByPairs(a, b), 1e-12);
  }
}

// The p-value counts, over every permutation drawn (more than one block of them, and counts that are
// not a multiple of a block), the splits whose statistic written out pair by pair reaches the
// observed one; the draws: the clusters shuffled again each time, the first n_a rows to a.
TEST(MmdTest, ThePValueCountsEveryPermutation) {
  std::mt19937_64 data(8);
  const Eigen::MatrixXd a = Normal(9, 2, 0.4, data), b = Normal(11, 2, 0, data);
  Eigen::MatrixXd pooled(20, 2);
  pooled << a, b;
  const double observed = Mmd2ByPairs(a, b);
  for (const int permutations : {1, 63, 64, 65, 150}) {
    std::mt19937_64 rng(permutations), replay(permutations);
    const MmdResult r = MmdTest(a, b, MmdOptions{permutations}, rng);
    std::vector<std::vector<int>> clusters;  // shuffled again from the last draw's order
    for (int i = 0; i < 20; ++i) clusters.push_back({i});
    int exceed = 0;
    for (int p = 0; p < permutations; ++p) {
      std::shuffle(clusters.begin(), clusters.end(), replay);
      Eigen::MatrixXd pa(9, 2), pb(11, 2);
      for (int i = 0; i < 20; ++i) (i < 9 ? pa.row(i) : pb.row(i - 9)) = pooled.row(clusters[i][0]);
      exceed += Mmd2ByPairs(pa, pb) >= observed;
    }
    EXPECT_DOUBLE_EQ(r.p_value, (1.0 + exceed) / (1.0 + permutations)) << permutations;
  }
}

// `clusters` clusters of `size` rows; each cluster shares an offset of sd `between` in every
// dimension (the ground under one placement), each row adds unit noise. Labels in `label`.
Eigen::MatrixXd Clustered(int clusters, int size, double between, std::mt19937_64& rng, std::vector<int>* label) {
  std::normal_distribution<double> z(0.0, 1.0);
  Eigen::MatrixXd m(clusters * size, 2);
  label->clear();
  for (int c = 0; c < clusters; ++c) {
    const Eigen::RowVector2d offset(between * z(rng), between * z(rng));
    for (int i = 0; i < size; ++i) {
      m.row(c * size + i) = offset + Eigen::RowVector2d(z(rng), z(rng));
      label->push_back(c);
    }
  }
  return m;
}

TEST(MmdTest, SingletonClustersAreTheSampleTest) {
  std::mt19937_64 data(3), r1(4), r2(4);
  const Eigen::MatrixXd a = Normal(20, 2, 0.5, data), b = Normal(25, 2, 0, data);
  std::vector<int> ca(20), cb(25);
  for (int i = 0; i < 20; ++i) ca[i] = 100 - i;  // any distinct labels
  for (int i = 0; i < 25; ++i) cb[i] = i;
  const MmdResult s = MmdTest(a, b, MmdOptions{300}, r1);
  const MmdResult c = MmdTest(a, b, ca, cb, MmdOptions{300}, r2);
  EXPECT_EQ(s.p_value, c.p_value);
  EXPECT_EQ(s.mmd2, c.mmd2);
}

// Two draws of placements from the same ground: the rows of one placement share its offset. Permuting
// rows treats them as independent and rejects far more often than its level; permuting whole
// placements keeps the level.
TEST(MmdTest, WholeClustersKeepTheLevelWhereRowsDoNot) {
  std::mt19937_64 rng(5);
  int by_rows = 0, by_clusters = 0;
  const int trials = 40;
  for (int t = 0; t < trials; ++t) {
    std::vector<int> ca, cb;
    const Eigen::MatrixXd a = Clustered(8, 5, 1.0, rng, &ca), b = Clustered(8, 5, 1.0, rng, &cb);
    by_rows += MmdTest(a, b, MmdOptions{200}, rng).p_value < 0.05;
    by_clusters += MmdTest(a, b, ca, cb, MmdOptions{200}, rng).p_value < 0.05;
  }
  EXPECT_LE(by_clusters, 8);  // 2 of 40 expected; 8 would be a p < 0.001 event for a valid test
  EXPECT_GE(by_rows, 12);
}

TEST(MmdTest, WholeClustersStillSeeAShift) {
  std::mt19937_64 rng(6);
  std::vector<int> ca, cb;
  Eigen::MatrixXd a = Clustered(20, 5, 0.3, rng, &ca);
  const Eigen::MatrixXd b = Clustered(20, 5, 0.3, rng, &cb);
  a.col(0).array() += 1.0;
  EXPECT_LT(MmdTest(a, b, ca, cb, MmdOptions{500}, rng).p_value, 0.01);
}

}  // namespace
}  // namespace dgmm::sim2real
