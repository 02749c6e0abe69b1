#include "tune/tune_k.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/tune/synthetic.h"
#include "tune/quadratic_surrogate.h"
#include "util/error.h"

namespace dgmm {
namespace {

// Relative slack for comparing k values produced by a sigmoid-bounded line search.
constexpr double kBoundSlack = 1e-9;

TEST(FitAndMaximise, RecoversTheVertexOfAQuadratic) {
  // L(u) = -3 (u - log 0.2)^2 + 10 sampled on a log grid: the maximiser is k = 0.2 exactly.
  std::vector<TuneKPoint> points;
  for (double u = std::log(0.05); u <= std::log(0.8) + 1e-9; u += 0.25) {
    const double d = u - std::log(0.2);
    points.push_back({std::exp(u), 10 - 3 * d * d, 0, 1, "grid"});
  }
  TuneKSummary summary;
  FitAndMaximise(points, 0.1, 0.4, 1.0, &summary);
  EXPECT_NEAR(std::log(summary.k), std::log(0.2), 1e-4);
  EXPECT_NEAR(summary.c, -3.0, 1e-4);
  EXPECT_NEAR(summary.Smoothed(0.2), 10.0, 1e-4);
}

TEST(FitAndMaximise, StaysInTheBracketWhenTheVertexIsOutside) {
  std::vector<TuneKPoint> points;
  for (double u = -3; u <= 0; u += 0.5) points.push_back({std::exp(u), u - 0.1 * u * u, 0, 1, ""});
  TuneKSummary summary;
  FitAndMaximise(points, std::exp(-1.0), std::exp(0.0), 1.0, &summary);  // vertex at u = 5
  EXPECT_LE(summary.k, 1.0 * (1 + kBoundSlack));
  EXPECT_GT(summary.k, std::exp(-0.05));  // pushed against the upper end
}

TEST(FitAndMaximise, RobustToOneStep) {
  // A piecewise-constant curve with one outlying step: the Cauchy loss keeps the fit's maximum
  // near the bulk's vertex (k = 1).
  std::vector<TuneKPoint> points;
  for (double u = -2; u <= 2 + 1e-9; u += 0.25) {
    double value = -std::round(4 * u * u) / 4;  // steps of 0.25
    if (std::abs(u - 0.5) < 1e-9) value -= 30;  // one bad evaluation
    points.push_back({std::exp(u), value, 0, 0.25, ""});
  }
  TuneKSummary summary;
  FitAndMaximise(points, std::exp(-0.5), std::exp(0.5), 0.25, &summary);
  EXPECT_NEAR(std::log(summary.k), 0.0, 0.15);
}

TEST(TuneK, ChosenKInBracketAndSmoothedMaximumBeatsGridNeighbours) {
  const SampleSet set = test::MakeTerrainSet(3, 30, 1.0, 9);
  TuneKOptions options;
  options.cv.folds = 5;
  options.cv.repeats = 2;
  options.k_min = 1e-2;
  // Not higher: beyond k ~ 4 every sample after the tenth merges with certainty, so all models
  // have one Gaussian per command and the curve is flat (a plateau, tested elsewhere).
  options.k_max = 3;
  options.grid_points = 6;
  options.refine_points = 2;
  options.plateau_tolerance = 1e-9;  // the quadratic's maximum, not the plateau rule
  options.init_scales.clear();
  options.prior_counts.clear();
  const TuneKSummary summary = TuneK(set, options);
  EXPECT_FALSE(summary.plateau) << summary.k_rule;
  EXPECT_GE(summary.k, summary.bracket_lo * (1 - kBoundSlack));
  EXPECT_LE(summary.k, summary.bracket_hi * (1 + kBoundSlack));
  EXPECT_LT(summary.c, 0);
  EXPECT_EQ(static_cast<int>(summary.curve.size()), 6 + 2 + 1);
  // The smoothed objective at k is at least its value at the grid points of the bracket.
  for (const auto& p : summary.curve) {
    if (p.role == "grid" && p.k >= summary.bracket_lo * (1 - kBoundSlack) &&
        p.k <= summary.bracket_hi * (1 + kBoundSlack)) {
      EXPECT_GE(summary.Smoothed(summary.k), summary.Smoothed(p.k) - 1e-9) << "k " << p.k;
    }
  }
  EXPECT_TRUE(std::isfinite(summary.log_likelihood));
  EXPECT_GT(summary.standard_error, 0);
  // Common random numbers: the chosen k's score is reproducible.
  const TuneKSummary again = TuneK(set, options);
  EXPECT_EQ(again.k, summary.k);
  EXPECT_EQ(again.log_likelihood, summary.log_likelihood);
}

TEST(FindPlateau, FlatObjectiveGivesTheRangeAndTheSimplestModel) {
  // L(k) rises then stays flat from k = 1 to 30 (within 0.5 nats); fewer Gaussians for larger k.
  std::vector<TuneKPoint> points;
  const double ks[] = {0.01, 0.1, 1, 3, 10, 30};
  const double ls[] = {-50, -20, -5.3, -5.0, -5.2, -5.4};
  const double kk[] = {9, 5, 3, 2, 1.5, 1};
  for (int i = 0; i < 6; ++i) points.push_back({ks[i], ls[i], 0, 1.0, "grid", kk[i]});
  const Plateau p = FindPlateau(points, 0.5);
  EXPECT_TRUE(p.flat);
  EXPECT_EQ(p.best, 3);
  EXPECT_EQ(p.members.size(), 4u);
  EXPECT_EQ(p.k_lo, 1);
  EXPECT_EQ(p.k_hi, 30);
  EXPECT_EQ(p.simplest, 5);  // one Gaussian per command at k = 30
  // A sharp optimum is not a plateau.
  const Plateau sharp = FindPlateau(points, 0.1);
  EXPECT_FALSE(sharp.flat);
  EXPECT_EQ(sharp.simplest, 3);
  // Sizes closer than kSameModelSize are the same size: the higher L among them is chosen, not
  // a lower one that saves a thousandth of a Gaussian per command.
  std::vector<TuneKPoint> near = {{1, -5.0, 0, 1.0, "grid", 1.0008}, {3, -5.4, 0, 1.0, "grid", 1.0},
                                  {10, -5.3, 0, 1.0, "grid", 1.2}};
  const Plateau same = FindPlateau(near, 0.5);
  EXPECT_EQ(same.members.size(), 3u);
  EXPECT_EQ(same.simplest, 0);
}

// Small folds, coarse grids, one coordinate cycle: fast TuneK runs.
TuneKOptions SmallOptions() {
  TuneKOptions options;
  options.cv.folds = 4;
  options.cv.repeats = 2;
  options.k_min = 0.1;
  options.k_max = 10;
  options.grid_points = 3;
  options.refine_points = 1;
  options.cycles = 1;
  options.init_scales = {0.1, 1.0, 10.0};
  options.prior_counts = {1.0, 16.0};
  return options;
}

TEST(TuneK, ReportsAPlateauOnAFlatCurve) {
  // Large k everywhere: one Gaussian per command at every grid point, the curve is flat.
  const SampleSet set = test::MakeTerrainSet(2, 20, 1.0, 3);
  TuneKOptions options = SmallOptions();
  options.cv.repeats = 1;
  options.k_min = 50;
  options.k_max = 500;
  options.init_scales.clear();  // k alone: one cycle, as with the default cycles
  options.prior_counts.clear();
  const TuneKSummary s = TuneK(set, options);
  EXPECT_TRUE(s.plateau);
  EXPECT_EQ(s.plateau_points, 4);
  EXPECT_NE(s.BriefReport().find("plateau"), std::string::npos) << s.BriefReport();
  EXPECT_EQ(s.components, 1.0);
}

// A grid of S0 scales far below what the data want: the best is the grid's top, so the tuner
// steps on beyond it (by the grid's ratio) instead of reporting the edge as the optimum.
TEST(TuneK, StepsBeyondAGridWhoseEdgeIsBest) {
  const SampleSet set = test::MakeTerrainSet(2, 30, 1.0, 5);
  TuneKOptions options = SmallOptions();
  options.cv.repeats = 1;
  options.joint = false;  // the coordinate step alone
  options.init_scales = {1e-4, 3e-4};
  options.cv.dgmm.initial_covariance_fraction = 1e-4;  // the start is on the grid too
  options.prior_counts.clear();
  const TuneKSummary s = TuneK(set, options);
  ASSERT_TRUE(s.init_scale_tuned);
  double largest = 0;
  for (const auto& p : s.scale_curve) largest = std::max(largest, p.init_scale);
  EXPECT_GT(largest, 3e-4 * 2);  // evaluated beyond the grid
  EXPECT_GT(s.init_scale, 3e-4 * 2) << "chose the grid's edge";
}

// The joint step starts from the cyclic choice, is never worse than it by more than the
// tolerance (and better when it accepts), and reports its plateau's ranges over every evaluation.
TEST(TuneK, JointStepIsNeverWorseThanTheCyclicChoice) {
  for (std::uint64_t seed : {3, 4}) {
    const SampleSet set = test::MakeTerrainSet(3, 24, 1.0, seed);
    TuneKOptions options = SmallOptions();
    options.joint = false;
    const TuneKSummary cyclic = TuneK(set, options);
    EXPECT_FALSE(cyclic.joint.run);
    options.joint = true;
    const TuneKSummary s = TuneK(set, options);
    const TuneJointStep& j = s.joint;
    ASSERT_TRUE(j.run);
    EXPECT_EQ(j.coordinates.size(), 3u);
    EXPECT_EQ(j.rounds, options.joint_rounds);
    EXPECT_EQ(j.start.k, cyclic.k);
    EXPECT_EQ(j.start.init_scale, cyclic.init_scale);
    EXPECT_EQ(j.start.prior_count, cyclic.prior_count);
    EXPECT_EQ(s.evaluations, cyclic.evaluations + j.evaluations);
    EXPECT_GT(j.evaluations, 0);
    EXPECT_GE(j.fit_points, QuadraticSurrogateParameters(3));
    EXPECT_GE(s.log_likelihood, cyclic.log_likelihood - j.tolerance);
    if (j.accepted) EXPECT_GT(s.log_likelihood, cyclic.log_likelihood);
    EXPECT_GE(s.k, options.k_min * (1 - kBoundSlack));
    EXPECT_LE(s.k, options.k_max * (1 + kBoundSlack));
    // The plateau: every member within the tolerance of the best, ranges spanning the members.
    ASSERT_FALSE(j.plateau.members.empty());
    const double best = j.points[j.plateau.best].log_likelihood;
    for (int i : j.plateau.members) {
      const TuneKPoint& p = j.points[i];
      EXPECT_GE(p.log_likelihood, best - j.tolerance);
      EXPECT_GE(p.k, j.plateau.k_lo);
      EXPECT_LE(p.k, j.plateau.k_hi);
      EXPECT_GE(p.init_scale, j.plateau.init_scale_lo);
      EXPECT_LE(p.init_scale, j.plateau.init_scale_hi);
      EXPECT_GE(p.prior_count, j.plateau.prior_count_lo);
      EXPECT_LE(p.prior_count, j.plateau.prior_count_hi);
    }
    EXPECT_NE(s.BriefReport().find("joint step"), std::string::npos);
    if (j.plateau.flat) EXPECT_NE(s.BriefReport().find("joint plateau"), std::string::npos);
  }
}

// A start the coordinate steps cannot leave (one-value grids for f and nu0, far from what the
// data want): the joint step moves f and nu0 on its own and is accepted.
TEST(TuneK, JointStepLeavesAPoorCyclicChoice) {
  const SampleSet set = test::MakeTerrainSet(3, 24, 1.0, 3);
  TuneKOptions options = SmallOptions();
  options.init_scales = {0.003};
  options.prior_counts = {64.0};
  options.cv.dgmm.initial_covariance_fraction = 0.003;
  options.cv.dgmm.prior_pseudo_count = 64.0;
  const TuneKSummary s = TuneK(set, options);
  ASSERT_TRUE(s.joint.run);
  EXPECT_TRUE(s.joint.accepted) << s.joint.rule;
  EXPECT_GT(s.log_likelihood, s.joint.start.log_likelihood + s.joint.tolerance);
  EXPECT_TRUE(s.init_scale != 0.003 || s.prior_count != 64.0);
}

TEST(TuneK, RejectsBadOptions) {
  const SampleSet set = test::MakeTerrainSet(2, 10, 1.0, 5);
  TuneKOptions options;
  options.k_min = 0;
  EXPECT_THROW(TuneK(set, options), InputError);
  options = TuneKOptions();
  options.k_max = options.k_min / 2;
  EXPECT_THROW(TuneK(set, options), InputError);
  options = TuneKOptions();
  options.cv.folds = 1;
  EXPECT_THROW(TuneK(set, options), InputError);
  options = TuneKOptions();
  options.grid_points = 2;
  EXPECT_THROW(TuneK(set, options), InputError);
  options = TuneKOptions();
  options.joint_rounds = 0;
  EXPECT_THROW(TuneK(set, options), InputError);
  EXPECT_THROW(TuneK(set.Subset({}), TuneKOptions()), InputError);
}

}  // namespace
}  // namespace dgmm
