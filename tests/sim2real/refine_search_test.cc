// The likelihood searches' shared parts: which searched points fit the real samples as well as the
// best one, with placements (not samples) as the independent units.
#include "sim2real/refine_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace dgmm::sim2real {
namespace {

// 40 placements of 5 samples; the best point's log-likelihoods are 0.
struct Rows {
  std::vector<int> placement;
  std::vector<Eigen::VectorXd> rows;
  Rows() {
    for (int g = 0; g < 40; ++g) {
      for (int e = 0; e < 5; ++e) placement.push_back(g);
    }
    rows.push_back(Eigen::VectorXd::Zero(200));
  }
};

TEST(RefineSearch, APointWithAConsistentDeficitDoesNotFitAsWell) {
  Rows r;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.5);
  Eigen::VectorXd worse(200);
  for (int i = 0; i < 200; ++i) worse(i) = -0.3 + noise(rng);  // 60 nats in all, SE about 7
  r.rows.push_back(worse);
  r.rows.push_back(Eigen::VectorXd::Constant(200, -1e-3));  // 0.2 nats in all, no spread: still worse
  const std::vector<bool> as_well = FitAsWellAsTheBest(r.rows, 0, r.placement, 2.0);
  EXPECT_TRUE(as_well[0]) << "the best is among them";
  EXPECT_FALSE(as_well[1]);
  EXPECT_FALSE(as_well[2]) << "a deficit with no spread at all is real";
}

// The same deficit per sample: a point whose samples err together within a placement (one sag
// decides a whole placement) is within the noise; spread over independent placements it is not.
TEST(RefineSearch, SamplesOfOnePlacementCountOnceInTheStandardError) {
  Rows r;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  Eigen::VectorXd d(200);
  for (int g = 0; g < 40; ++g) {
    const double shared = noise(rng);
    for (int e = 0; e < 5; ++e) d(5 * g + e) = -0.25 + 1.5 * shared;
  }
  d.array() -= d.mean() + 0.25;  // a deficit of exactly 50 nats
  r.rows.push_back(d);
  EXPECT_TRUE(FitAsWellAsTheBest(r.rows, 0, r.placement, 2.0)[1]) << "SE about 47 nats over 40 placements";
  std::vector<int> every_sample_alone(200);
  for (int i = 0; i < 200; ++i) every_sample_alone[i] = i;
  EXPECT_FALSE(FitAsWellAsTheBest(r.rows, 0, every_sample_alone, 2.0)[1]) << "SE about 21 nats over 200 samples";
}

TEST(RefineSearch, ALargerZAdmitsMorePoints) {
  Rows r;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(200);
  for (int g = 0; g < 40; ++g) d(5 * g) = g % 2 ? -2.0 : 1.0;  // 20 nats deficit, SE 9.5
  r.rows.push_back(d);
  EXPECT_FALSE(FitAsWellAsTheBest(r.rows, 0, r.placement, 1.0)[1]);
  EXPECT_TRUE(FitAsWellAsTheBest(r.rows, 0, r.placement, 3.0)[1]);
}

// Where the deficit cannot be told (lengths differ, one placement, no spread with z infinite, not a
// number), FitsAsWellAs answers what its caller asks for: "no" when collecting points that fit as
// well, "yes" for the payload's middle line, which is recorded unless it clearly fits worse.
// Points at values 1..5 whose log-likelihoods per sample are `means` plus placement noise.
std::vector<Eigen::VectorXd> Scored(const std::vector<double>& means, double sd) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, sd);
  std::vector<Eigen::VectorXd> rows;
  for (double m : means) {
    Eigen::VectorXd r(200);
    for (int g = 0; g < 40; ++g) r.segment(5 * g, 5).setConstant(m + noise(rng));
    rows.push_back(r);
  }
  return rows;
}

TEST(RefineSearch, ScoresThatRiseToOnePeakHaveNoDip) {
  const Rows r;
  const std::vector<double> values = {5, 1, 4, 2, 3};  // in any order
  EXPECT_FALSE(DeepestDip(Scored({-0.5, -0.8, -0.2, -0.4, 0}, 0.01), values, r.placement, 2.0).Found());
  EXPECT_FALSE(DeepestDip(Scored({-0.5, -0.8}, 0.01), {1, 2}, r.placement, 2.0).Found()) << "two points";
}

TEST(RefineSearch, APointWorseThanPointsOnEitherSideIsTheDip) {
  const Rows r;
  // By value: 1: -0.3, 2: -0.6, 3: -0.1, 4: -0.9, 5: 0. The point at 4 lies 0.8 below the best to
  // its left (3) and 0.9 below the one to its right (5); the point at 2, 0.3 and 0.6: a shallower dip.
  const std::vector<double> values = {1, 2, 3, 4, 5};
  const ScoreDip dip = DeepestDip(Scored({-0.3, -0.6, -0.1, -0.9, 0}, 0.05), values, r.placement, 2.0);
  ASSERT_TRUE(dip.Found());
  EXPECT_EQ(dip.at, 3);
  EXPECT_EQ(dip.left, 2);
  EXPECT_EQ(dip.right, 4);
  EXPECT_NEAR(dip.below.sum, 0.8 * 200, 0.05 * 5 * 40);
  EXPECT_NEAR(dip.above.sum, 0.9 * 200, 0.05 * 5 * 40);
  EXPECT_GT(dip.below.se, 0);
}

TEST(RefineSearch, ADipWithinThePlacementsNoiseIsNone) {
  const Rows r;
  // The same means with placement noise of sd 3 nats per sample: SE of a deficit about 130 nats.
  EXPECT_FALSE(DeepestDip(Scored({-0.3, -0.6, -0.1, -0.9, 0}, 3.0), {1, 2, 3, 4, 5}, r.placement, 2.0).Found());
}

TEST(RefineSearch, WhatCannotBeToldIsTheCallersAnswer) {
  Rows r;
  const UnitIds units = NumberUnits(r.placement);
  const Eigen::VectorXd best = r.rows[0];
  for (bool untold : {false, true}) {
    EXPECT_EQ(FitsAsWellAs(best, Eigen::VectorXd::Zero(199), units, 2.0, untold), untold);
    EXPECT_EQ(FitsAsWellAs(best, best, NumberUnits(std::vector<int>(200, 0)), 2.0, untold), untold);
    EXPECT_EQ(FitsAsWellAs(best, best, units, INFINITY, untold), untold) << "SE 0 times infinity";
    EXPECT_EQ(FitsAsWellAs(best, Eigen::VectorXd::Constant(200, NAN), units, 2.0, untold), untold);
    EXPECT_FALSE(FitsAsWellAs(best, Eigen::VectorXd::Constant(200, -1.0), units, 2.0, untold))
        << "a deficit with no spread is told";
  }
  Eigen::VectorXd d = Eigen::VectorXd::Zero(200);
  for (int g = 0; g < 40; ++g) d(5 * g) = g % 2 ? -2.0 : 1.0;  // 20 nats deficit, SE 9.5
  EXPECT_TRUE(FitsAsWellAs(best, d, units, INFINITY, false));
  EXPECT_FALSE(FitsAsWellAs(best, d, units, 1.0, true));
}

}  // namespace
}  // namespace dgmm::sim2real
