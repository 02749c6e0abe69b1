// MMD permutation test and Benjamini-Hochberg against closed forms and known cases.
#include "sim2real/two_sample.h"

#include <gtest/gtest.h>

#include <random>

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

}  // namespace
}  // namespace dgmm::sim2real
