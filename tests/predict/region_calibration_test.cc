// lib/predict/region_calibration.h: regions widened by held-out episodes hold their shares of
// outcomes when the model's spread is too narrow, stay about as they are when it is right, and bad
// calibration sets are refused naming the part.
#include "predict/region_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "predict/predict.h"
#include "util/error.h"

namespace dgmm::predict {
namespace {

// One command "walk": dx ~ N(0.1, 0.01^2), dy ~ N(0, 0.01^2), dyaw ~ N(0.1, 0.05^2), independent.
MotionModel Walk() {
  MotionModel m;
  m.pose_dim = 3;
  m.pose_names = {"dx", "dy", "dyaw"};
  m.command_labels = {{0, "walk"}};
  Mixture mix(3);
  mix.Add(1.0, Gaussian(Eigen::Vector3d(0.1, 0, 0.1), Eigen::Vector3d(1e-4, 1e-4, 2.5e-3).asDiagonal()));
  m.mixtures[0] = mix;
  return m;
}

// Episodes of `steps` commands whose pose changes deviate from Walk()'s mean `spread` times as much
// as the model says.
SampleSet Episodes(int episodes, int steps, double spread, std::uint64_t seed) {
  const MotionModel m = Walk();
  const Gaussian& g = m.mixtures.at(0).component(0);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  SampleSet s;
  s.commands = Eigen::MatrixXd::Zero(1, 0);
  s.command_labels = {"walk"};
  s.x_names = {"dx", "dy", "dyaw"};
  s.x_units = {"m", "m", "rad"};
  s.x.resize(episodes * steps, 3);
  s.command = Eigen::VectorXi::Zero(episodes * steps);
  s.episode.resize(episodes * steps);
  s.step.resize(episodes * steps);
  for (int row = 0; row < episodes * steps; ++row) {
    const Eigen::Vector3d eps = Eigen::Vector3d::NullaryExpr([&] { return normal(rng); });
    s.x.row(row) = (g.mean() + spread * (g.cholesky_l() * eps)).transpose();
    s.episode[row] = row / steps;
    s.step[row] = row % steps;
  }
  return s;
}

// Share of the episodes' outcomes after `steps` commands inside the predicted regions, per level.
Eigen::Vector2d Coverage(const SampleSet& set, int steps, const PredictOptions& options) {
  const MotionModel m = Walk();
  const std::vector<Step> sequence(steps, Step{0, {}});
  const Prediction p = Predict(m, Eigen::Vector3d::Zero(), sequence, options);
  Eigen::Vector2d inside = Eigen::Vector2d::Zero();
  const int episodes = set.size() / steps;
  for (int e = 0; e < episodes; ++e) {
    const Eigen::MatrixXd path = ComposePath(m, Eigen::Vector3d::Zero(), set.x.middleRows(e * steps, steps), options);
    const double d2 = p.steps.back().RegionDistance2(path.row(steps - 1).head<2>().transpose());
    for (int l = 0; l < 2; ++l) inside[l] += d2 <= p.steps.back().region_r2[l];
  }
  return inside / episodes;
}

PredictOptions Options(int trajectories = 4000) {
  PredictOptions o;
  o.trajectories = trajectories;
  o.seed = 3;
  return o;
}

TEST(CalibrateRegions, ATooNarrowModelsRegionsAreWidenedToHoldTheirShares) {
  const SampleSet held_out = Episodes(400, 5, 1.5, 1), fresh = Episodes(400, 5, 1.5, 2);
  const RegionCalibration cal = CalibrateRegions(Walk(), held_out, Options(500));
  ASSERT_EQ(cal.factor.rows(), 5);
  ASSERT_EQ(cal.factor.cols(), 2);
  EXPECT_EQ(cal.episodes[4], 400);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(cal.factor(k, 1), 2.25, 0.5) << "the spread is 1.5x: r2 2.25x";
  const Eigen::Vector2d before = Coverage(fresh, 5, Options());
  EXPECT_LT(before[1], 0.8);
  PredictOptions o = Options();
  o.calibration = cal;
  const Eigen::Vector2d after = Coverage(fresh, 5, o);
  EXPECT_NEAR(after[0], 0.5, 0.08);
  EXPECT_NEAR(after[1], 0.9, 0.05);
}

TEST(CalibrateRegions, ARightModelKeepsItsRegions) {
  const RegionCalibration cal = CalibrateRegions(Walk(), Episodes(400, 5, 1.0, 5), Options(500));
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(cal.factor(k, 0), 1.0, 0.3) << k;
    EXPECT_NEAR(cal.factor(k, 1), 1.0, 0.3) << k;
  }
}

TEST(CalibrateRegions, ShortEpisodesCalibrateTheHorizonsTheyReach) {
  SampleSet set = Episodes(30, 4, 1.0, 7);
  CalibrationOptions c;
  c.min_episodes = 30;
  const RegionCalibration cal = CalibrateRegions(Walk(), set, Options(200), c);
  EXPECT_EQ(cal.factor.rows(), 4);
  EXPECT_EQ(cal.Factor(9, 1), cal.factor(3, 1)) << "later steps take the last horizon's factor";
  set.step[set.size() - 1] = 9;  // a gap: that episode reaches 3 steps only
  EXPECT_EQ(CalibrateRegions(Walk(), set, Options(200), c).factor.rows(), 3);
}

TEST(CalibrateRegions, ABadSetOrOptionsAreRefusedNamingThePart) {
  SampleSet no_episodes = Episodes(30, 4, 1.0, 7);
  no_episodes.episode.resize(0);
  no_episodes.step.resize(0);
  try {
    CalibrateRegions(Walk(), no_episodes, Options(), {}, "held.h5");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("held.h5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("episode"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CalibrateRegions(Walk(), Episodes(5, 4, 1.0, 7), Options()), InputError) << "fewer than 20 episodes";
  PredictOptions bad_levels = Options(200);
  bad_levels.region_levels = {0.5, 1.0};
  EXPECT_THROW(CalibrateRegions(Walk(), Episodes(30, 4, 1.0, 7), bad_levels), InputError);
  CalibrationOptions no_episodes_needed;
  no_episodes_needed.min_episodes = 0;
  EXPECT_THROW(CalibrateRegions(Walk(), Episodes(30, 4, 1.0, 7), Options(200), no_episodes_needed), InputError);
  EXPECT_THROW(CalibrateRegions(Walk(), Episodes(30, 4, 1.0, 7), Options(1)), InputError) << "one trajectory has no spread";
  PredictOptions o = Options();
  o.calibration.levels = {0.5, 0.9};
  o.calibration.factor = Eigen::MatrixXd::Constant(3, 1, 1.0);  // one level's factors for two levels
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("calibration"), std::string::npos) << error;
}

TEST(ComposePath, ComposesRecordedChangesAsPredictDoes) {
  Eigen::MatrixXd x(2, 3);
  x << 0.1, 0, M_PI / 2, 0.1, 0, 0;
  const Eigen::MatrixXd path = ComposePath(Walk(), Eigen::Vector3d(1, 2, 0), x, Options());
  EXPECT_NEAR(path(1, 0), 1.1, 1e-12);
  EXPECT_NEAR(path(1, 1), 2.1, 1e-12);
  EXPECT_NEAR(path(1, 3), M_PI / 2, 1e-12);
}

}  // namespace
}  // namespace dgmm::predict
