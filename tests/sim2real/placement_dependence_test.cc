// The placement-dependence test against cases with and without a shared effect per placement.
#include "sim2real/placement_dependence.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace dgmm::sim2real {
namespace {

// `placements` placements of `per` executions, one command each (command = placement % commands,
// with its own mean); every execution of a placement shares an offset of sd `shared`.
Samples Set(int placements, int per, int commands, double shared, std::mt19937_64& rng) {
  std::normal_distribution<double> z(0.0, 1.0);
  Samples s;
  s.x.resize(placements * per, 2);
  s.z = Eigen::MatrixXd::Zero(placements * per, 0);
  for (int p = 0; p < placements; ++p) {
    const int c = p % commands;
    const Eigen::RowVector2d offset(shared * z(rng) + 3.0 * c, shared * z(rng) - c);
    for (int e = 0; e < per; ++e) {
      s.x.row(p * per + e) = offset + Eigen::RowVector2d(z(rng), z(rng));
      s.command.push_back(c);
      s.episode.push_back(p);
      s.first_execution.push_back(e == 0);
    }
  }
  return s;
}

// Residuals about each command's own mean (the test's input: what the command leaves).
Eigen::MatrixXd Residuals(const Samples& s, int commands) {
  Eigen::MatrixXd r = s.x;
  for (int c = 0; c < commands; ++c) {
    Eigen::RowVector2d mean = Eigen::RowVector2d::Zero();
    int n = 0;
    for (int i = 0; i < s.size(); ++i) {
      if (s.command[i] == c) mean += s.x.row(i), ++n;
    }
    for (int i = 0; i < s.size(); ++i) {
      if (s.command[i] == c) r.row(i) -= mean / n;
    }
  }
  return r;
}

PlacementDependence Draw(double shared, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Samples sim = Set(60, 5, 6, shared, rng), real = Set(30, 5, 6, shared, rng);
  return TestPlacementDependence(sim, Residuals(sim, 6), real, Residuals(real, 6), PlacementDependenceOptions{}, 1);
}

TEST(PlacementDependence, ASharedEffectPerPlacementIsFound) {
  const PlacementDependence d = Draw(0.7, 1);
  EXPECT_LT(d.p_value, 0.01);
  EXPECT_TRUE(d.dependent);
}

TEST(PlacementDependence, IndependentExecutionsAreNotFlaggedOften) {
  int flagged = 0;
  for (std::uint64_t seed = 10; seed < 30; ++seed) flagged += Draw(0.0, seed).dependent;
  EXPECT_LE(flagged, 4);  // 1 of 20 expected at alpha 0.05
}

TEST(PlacementDependence, SetsWithoutPlacementsGiveNoEvidence) {
  std::mt19937_64 rng(2);
  Samples s = Set(40, 1, 4, 1.0, rng);
  const PlacementDependence d =
      TestPlacementDependence(s, Residuals(s, 4), s, Residuals(s, 4), PlacementDependenceOptions{}, 1);
  EXPECT_EQ(d.p_value, 1.0);
  EXPECT_FALSE(d.dependent);
}

// x less its command's mean: what the command leaves.
Eigen::MatrixXd CommandResiduals(const Samples& s) {
  Eigen::MatrixXd r = s.x;
  std::map<int, std::pair<Eigen::RowVectorXd, int>> sum;
  for (int i = 0; i < s.size(); ++i) {
    auto& [m, n] = sum.try_emplace(s.command[i], Eigen::RowVectorXd::Zero(s.pose_dim()), 0).first->second;
    m += s.x.row(i), ++n;
  }
  for (int i = 0; i < s.size(); ++i) r.row(i) -= sum[s.command[i]].first / sum[s.command[i]].second;
  return r;
}

TEST(PlacementDependence, TheIntraclassCorrelationIsTheSharedShareOfTheVariance) {
  std::mt19937_64 rng(5);
  // An offset of sd 1 shared by a placement's executions, noise of sd 1 of their own: half the
  // variance is shared.
  const Samples dependent = Set(300, 5, 3, 1.0, rng), independent = Set(300, 5, 3, 0.0, rng);
  const Eigen::VectorXd rho = WithinPlacementCorrelation(CommandResiduals(dependent), dependent.episode);
  ASSERT_EQ(rho.size(), 2);
  EXPECT_NEAR(rho(0), 0.5, 0.08);
  EXPECT_NEAR(rho(1), 0.5, 0.08);
  EXPECT_LT(WithinPlacementCorrelation(CommandResiduals(independent), independent.episode).maxCoeff(), 0.06);
  // Every sample its own placement: nothing shared to measure.
  std::vector<int> own(dependent.size());
  for (int i = 0; i < dependent.size(); ++i) own[i] = i;
  EXPECT_EQ(WithinPlacementCorrelation(CommandResiduals(dependent), own).maxCoeff(), 0.0);
}

TEST(PlacementDependence, OptionsAreChecked) {
  PlacementDependenceOptions o;
  o.alpha = 1.5;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("alpha"), std::string::npos);
}

}  // namespace
}  // namespace dgmm::sim2real
