#include "em/kmeans.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace dgmm {
namespace {

// n points around each of the given centres (rows), spread sigma; rows grouped by centre.
Eigen::MatrixXd Clusters(const Eigen::MatrixXd& centres, int n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  Eigen::MatrixXd X(centres.rows() * n, centres.cols());
  for (Eigen::Index c = 0; c < centres.rows(); ++c)
    for (int i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < centres.cols(); ++j)
        X(c * n + i, j) = centres(c, j) + normal(rng);
  return X;
}

TEST(KMeansOptionsTest, RejectsInvalid) {
  std::string error;
  EXPECT_TRUE(KMeansOptions{}.IsValid(&error));
  EXPECT_TRUE(error.empty());
  KMeansOptions o;
  o.clusters = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_FALSE(error.empty());
  o = {};
  o.relative_tolerance = -1;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(KMeansPlusPlusTest, DistinctSeedsOnDistinctPointsAndReproducible) {
  Eigen::MatrixXd X = Clusters(Eigen::MatrixXd::Random(5, 3) * 10, 30, 0.5, 3);
  std::mt19937_64 a(7), b(7);
  const std::vector<int> first = KMeansPlusPlus(X, 5, a);
  EXPECT_EQ(first, KMeansPlusPlus(X, 5, b));
  EXPECT_EQ(std::set<int>(first.begin(), first.end()).size(), 5u);
  for (int i : first) {
    EXPECT_GE(i, 0);
    EXPECT_LT(i, X.rows());
  }
}

TEST(KMeansTest, LabelsAreNearestCentresAndCentresAreMeans) {
  Eigen::MatrixXd centres(3, 2);
  centres << 0, 0, 10, 0, 0, 10;
  const Eigen::MatrixXd X = Clusters(centres, 50, 1.0, 11);
  std::mt19937_64 rng(1);
  KMeansOptions options;
  options.clusters = 3;
  options.relative_tolerance = 0;  // run to strict convergence
  const KMeansResult r = FitKMeans(X, options, rng);
  ASSERT_TRUE(r.converged);
  const Eigen::MatrixXd D = SquaredDistances(X, r.centers);
  double inertia = 0;
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    Eigen::Index best;
    D.row(i).minCoeff(&best);
    EXPECT_EQ(r.labels(i), best);
    inertia += D(i, best);
  }
  EXPECT_NEAR(r.inertia, inertia, 1e-9 * inertia);
  for (int k = 0; k < 3; ++k) {
    Eigen::RowVectorXd sum = Eigen::RowVectorXd::Zero(2);
    int count = 0;
    for (Eigen::Index i = 0; i < X.rows(); ++i)
      if (r.labels(i) == k) sum += X.row(i), ++count;
    ASSERT_GT(count, 0);
    EXPECT_LT((sum / count - r.centers.row(k)).norm(), 1e-10);
  }
  // Every true cluster ends up under one label (well separated).
  for (int c = 0; c < 3; ++c)
    for (int i = 1; i < 50; ++i) EXPECT_EQ(r.labels(c * 50 + i), r.labels(c * 50));
}

TEST(KMeansTest, DuplicatePointsKeepEveryLabelInRange) {
  Eigen::MatrixXd X(4, 2);
  X << 1, 1, 1, 1, 1, 1, 2, 2;
  std::mt19937_64 rng(0);
  KMeansOptions options;
  options.clusters = 4;
  const KMeansResult r = FitKMeans(X, options, rng);
  EXPECT_TRUE(r.centers.allFinite());
  EXPECT_TRUE((r.labels.array() >= 0).all() && (r.labels.array() < 4).all());
  EXPECT_NEAR(r.inertia, 0.0, 1e-12);
}

}  // namespace
}  // namespace dgmm
