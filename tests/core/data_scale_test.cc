// S0 and the floor resolved from the data's scale (lib/core/data_scale.h), and the warning when a
// user's S0 is far from it.
#include "core/data_scale.h"

#include <gtest/gtest.h>

#include <random>

#include "core/motion_model.h"
#include "util/error.h"

namespace dgmm {
namespace {

// Two commands in 2-D at metre scale, with episodes; x only.
SampleSet MetreSet(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  SampleSet set;
  set.commands = Eigen::MatrixXd::Zero(2, 1);
  set.commands(1, 0) = 1;
  set.command_labels = {"a", "b"};
  set.command_dim_names = {"v"};
  const int rows = 60;
  set.command.resize(rows);
  set.x.resize(rows, 2);
  set.x_names = {"dx", "dyaw"};
  set.x_units = {"m", "rad"};
  for (int i = 0; i < rows; ++i) {
    const int c = i % 2;
    set.command(i) = c;
    set.x(i, 0) = 0.1 * c + 0.005 * n(rng);  // commands differ in mean: not within-command
    set.x(i, 1) = -0.02 * c + 0.001 * n(rng);
  }
  set.z.resize(rows, 0);
  return set;
}

// v_j by definition (two passes): sum over commands of squared deviations from the command
// mean, over N - C.
Eigen::VectorXd PooledByHand(const SampleSet& set) {
  Eigen::VectorXd ss = Eigen::VectorXd::Zero(set.pose_dim());
  int commands = 0;
  for (int c = 0; c < set.num_commands(); ++c) {
    std::vector<int> rows;
    for (int i = 0; i < set.size(); ++i) {
      if (set.command(i) == c) rows.push_back(i);
    }
    if (rows.empty()) continue;
    ++commands;
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(set.pose_dim());
    for (int i : rows) mean += set.x.row(i).transpose();
    mean /= static_cast<double>(rows.size());
    for (int i : rows) ss += (set.x.row(i).transpose() - mean).array().square().matrix();
  }
  return ss / static_cast<double>(set.size() - commands);
}

// Round-off of a streamed (Welford) variance against the two-pass one, relative.
constexpr double kVarianceTolerance = 1e-10;

TEST(DataScaleTest, InitialCovarianceFromDataEqualsTheDocumentedRule) {
  const SampleSet set = MetreSet(3);
  const Eigen::VectorXd v = PooledByHand(set);
  const Eigen::VectorXd got = PooledWithinCommandVariance(set, true);
  ASSERT_EQ(got.size(), 2);
  for (int j = 0; j < 2; ++j) EXPECT_NEAR(got[j], v[j], kVarianceTolerance * v[j]) << j;
  // Within-command, not total: the command means are 0.1 m apart, far more than the noise.
  EXPECT_LT(got[0], 1e-4);

  DgmmOptions o;  // data rule by default
  o.initial_covariance_fraction = 0.25;
  o.covariance_floor_relative = 1e-3;
  MotionModelOptions mo;
  mo.dgmm = o;
  std::string warning = "stale";
  const MotionModelOptions r = ResolveMotionModelOptions(set, mo, &warning);
  ASSERT_EQ(r.dgmm.initial_covariance_diagonal.size(), 2);
  for (int j = 0; j < 2; ++j) {
    EXPECT_NEAR(r.dgmm.initial_covariance_diagonal[j], 0.25 * v[j], kVarianceTolerance * v[j]);
  }
  EXPECT_NEAR(r.dgmm.covariance_floor, 1e-3 * v.minCoeff(), kVarianceTolerance * v.minCoeff());
  EXPECT_TRUE(warning.empty());
  // And the learned model carries the resolved options.
  const MotionModel model = LearnMotionModel(set, mo);
  EXPECT_EQ(model.dgmm_options.initial_covariance_diagonal, r.dgmm.initial_covariance_diagonal);
  EXPECT_EQ(model.dgmm_options.covariance_floor, r.dgmm.covariance_floor);
}

TEST(DataScaleTest, FallsBackToTotalVarianceThenOne) {
  DataScaleAccumulator one_per_command(2);
  one_per_command.Add(0, Eigen::Vector2d(1, 5));
  one_per_command.Add(1, Eigen::Vector2d(3, 5));  // N = C: no within-command degrees of freedom
  const Eigen::VectorXd v = one_per_command.PooledVariance();
  EXPECT_DOUBLE_EQ(v[0], 2.0);  // total variance of {1, 3}
  EXPECT_DOUBLE_EQ(v[1], 1.0);  // constant everywhere
}

TEST(DataScaleTest, WarnsWhenTheUsersInitialCovarianceIsFarFromTheDataScale) {
  const SampleSet set = MetreSet(4);
  MotionModelOptions mo;
  std::string warning;
  mo.dgmm.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;
  ResolveMotionModelOptions(set, mo, &warning);
  EXPECT_NE(warning.find("identity"), std::string::npos) << warning;
  EXPECT_NE(warning.find("dyaw"), std::string::npos) << warning;  // the worst dimension
  EXPECT_NE(warning.find("swallow"), std::string::npos) << warning;

  const Eigen::VectorXd v = PooledWithinCommandVariance(set, true);
  mo.dgmm.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kUser;
  mo.dgmm.initial_covariance_diagonal = 0.5 * v;  // on scale: no warning
  ResolveMotionModelOptions(set, mo, &warning);
  EXPECT_TRUE(warning.empty()) << warning;
  mo.dgmm.initial_covariance_diagonal = v / 1000.0;  // needles
  ResolveMotionModelOptions(set, mo, &warning);
  EXPECT_NE(warning.find("needles"), std::string::npos) << warning;
  mo.dgmm.initial_covariance_diagonal = Eigen::Vector3d(1, 1, 1);  // wrong size
  EXPECT_THROW(ResolveMotionModelOptions(set, mo, &warning), InputError);
}

}  // namespace
}  // namespace dgmm
