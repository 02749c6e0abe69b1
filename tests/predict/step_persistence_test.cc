// lib/predict/step_persistence.h: the persistence of deviations is recovered from episodes drawn
// with a known one, and widens predictions over many steps without changing a single step.
#include "predict/step_persistence.h"

#include <gtest/gtest.h>

#include <random>

#include "predict/predict.h"
#include "util/error.h"

namespace dgmm::predict {
namespace {

// One command "fwd": dx ~ N(0.1, 0.01^2), dy ~ N(0, 0.01^2), dyaw ~ N(0, 0.02^2), independent.
MotionModel Forward() {
  MotionModel m;
  m.pose_dim = 3;
  m.pose_names = {"dx", "dy", "dyaw"};
  m.command_labels = {{0, "fwd"}};
  Mixture mix(3);
  mix.Add(1.0, Gaussian(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(1e-4, 1e-4, 4e-4).asDiagonal()));
  m.mixtures[0] = mix;
  return m;
}

// Episodes of `steps` commands drawn from Forward() with the standard normal deviations of dyaw
// correlated by (a, phi) = (0.5, 0.7) and those of dx, dy independent.
SampleSet Episodes(int episodes, int steps, std::uint64_t seed) {
  const MotionModel m = Forward();
  StepPersistence p;
  p.shared = Eigen::Vector3d(0, 0, 0.5);
  p.decay = Eigen::Vector3d(0, 0, 0.7);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  SampleSet s;
  s.commands = Eigen::MatrixXd::Zero(1, 0);
  s.command_labels = {"fwd"};
  s.x_names = m.pose_names;
  s.x_units = {"m", "m", "rad"};
  s.x.resize(episodes * steps, 3);
  s.command = Eigen::VectorXi::Zero(episodes * steps);
  s.episode.resize(episodes * steps);
  s.step.resize(episodes * steps);
  const Gaussian& g = m.mixtures.at(0).component(0);
  for (int e = 0; e < episodes; ++e) {
    Eigen::Vector3d u = Eigen::Vector3d::NullaryExpr([&] { return normal(rng); });
    for (int t = 0; t < steps; ++t) {
      if (t > 0) u = (u.array() * p.decay.array() + Eigen::Array3d::NullaryExpr([&] { return normal(rng); }) * (1 - p.decay.array().square()).sqrt()).matrix();
      const Eigen::Array3d w = Eigen::Array3d::NullaryExpr([&] { return normal(rng); });
      const Eigen::Vector3d eps = (u.array() * p.shared.array().sqrt() + w * (1 - p.shared.array()).sqrt()).matrix();
      const int row = e * steps + t;
      s.x.row(row) = (g.mean() + g.cholesky_l() * eps).transpose();
      s.episode[row] = e;
      s.step[row] = t;
    }
  }
  return s;
}

TEST(EstimatePersistence, RecoversTheShareAndDecayOfAKnownProcess) {
  const PersistenceSummary s = EstimatePersistence(Forward(), Episodes(400, 10, 3));
  EXPECT_EQ(s.episodes, 400);
  EXPECT_EQ(s.pairs[0], 400 * 9);
  EXPECT_NEAR(s.lag_correlation(2, 0), 0.35, 0.05);  // a phi
  EXPECT_NEAR(s.residual_rms[0], 1.0, 0.05);  // the model describes the set
  EXPECT_NEAR(s.persistence.shared[2], 0.5, 0.1);
  EXPECT_NEAR(s.persistence.decay[2], 0.7, 0.1);
  for (int d = 0; d < 2; ++d) {
    EXPECT_LT(std::abs(s.lag_correlation(d, 0)), 0.06) << d;
    EXPECT_LT(s.persistence.shared[d] * s.persistence.decay[d], 0.06) << d;
  }
}

// First steps drawn at half the model's spread in dx: s = 0.5 for dx, 1 for the others; a
// prediction from standing draws its first step at that spread, one already walking at the model's.
TEST(EstimatePersistence, TheFirstStepFromStandingHasItsOwnSpread) {
  SampleSet s = Episodes(400, 5, 4);
  for (int i = 0; i < s.size(); ++i) {
    if (s.step[i] == 0) s.x(i, 0) = 0.1 + 0.5 * (s.x(i, 0) - 0.1);
  }
  const PersistenceSummary p = EstimatePersistence(Forward(), s);
  EXPECT_EQ(p.first_steps, 400);
  EXPECT_NEAR(p.persistence.first_scale[0], 0.5, 0.05);
  EXPECT_NEAR(p.persistence.first_scale[1], 1.0, 0.1);
  PredictOptions o;
  o.trajectories = 4000;
  o.persistence = p.persistence;
  const double standing = Predict(Forward(), Eigen::Vector3d::Zero(), {{0, {}}}, o).steps[0].covariance(0, 0);
  o.from_rest = false;
  const double walking = Predict(Forward(), Eigen::Vector3d::Zero(), {{0, {}}}, o).steps[0].covariance(0, 0);
  EXPECT_NEAR(standing / walking, 0.25, 0.05);
}

TEST(EstimatePersistence, NeedsEpisodesOfConsecutiveSteps) {
  SampleSet s = Episodes(40, 3, 1);
  s.episode.resize(0);
  s.step.resize(0);
  try {
    EstimatePersistence(Forward(), s, {}, "walk.h5");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("walk.h5: episode:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(EstimatePersistence(Forward(), Episodes(10, 2, 1)), InputError);  // 10 pairs < 30
}

// Position x after n forward steps: its variance grows with n^2 rather than n when dx deviations persist.
TEST(Predict, PersistentDeviationsWidenLongHorizonsOnly) {
  PredictOptions o;
  o.trajectories = 4000;
  const std::vector<Step> steps(10, Step{0, {}});
  const Prediction independent = Predict(Forward(), Eigen::Vector3d::Zero(), steps, o);
  o.persistence.shared = Eigen::Vector3d(1, 0, 0);
  o.persistence.decay = Eigen::Vector3d(0.9, 0, 0);
  const Prediction persistent = Predict(Forward(), Eigen::Vector3d::Zero(), steps, o);
  const double first = persistent.steps[0].covariance(0, 0) / independent.steps[0].covariance(0, 0);
  EXPECT_NEAR(first, 1.0, 0.15);
  const double last = persistent.steps[9].covariance(0, 0) / independent.steps[9].covariance(0, 0);
  // sum_{i,j} 0.9^|i-j| / 10 = 7.3 for ten steps
  EXPECT_NEAR(last, 7.3, 1.0);
  EXPECT_NEAR(persistent.steps[9].mean[0], 1.0, 0.01);
}

TEST(Predict, RefusesAPersistenceOfTheWrongSizeOrRange) {
  PredictOptions o;
  o.persistence.shared = Eigen::Vector2d(0.5, 0.5);
  o.persistence.decay = Eigen::Vector2d(0.5, 0.5);
  EXPECT_THROW(Predict(Forward(), Eigen::Vector3d::Zero(), {{0, {}}}, o), InputError);
  o.persistence.shared = Eigen::Vector3d(0.5, 1.5, 0);
  o.persistence.decay = Eigen::Vector3d(0.5, 0.5, 0);
  EXPECT_THROW(Predict(Forward(), Eigen::Vector3d::Zero(), {{0, {}}}, o), InputError);
}

}  // namespace
}  // namespace dgmm::predict
