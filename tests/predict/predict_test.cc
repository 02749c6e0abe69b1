// lib/predict/predict.h on small hand-made models whose outcome is known.
#include "predict/ground_terrain.h"
#include "predict/predict.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"

namespace dgmm::predict {
namespace {

// Commands 0: forward 0.1 m; 1: a quarter turn left; each with tiny noise. Planar (dx, dy, dyaw)
// and, with terrain, dx grows with the terrain value: dx = 0.1 + 0.5 z.
MotionModel Planar(bool terrain) {
  MotionModel m;
  m.pose_dim = 3;
  m.terrain_dim = terrain ? 1 : 0;
  m.pose_names = {"dx", "dy", "dyaw"};
  if (terrain) m.terrain_names = {"pitch"};
  m.command_labels = {{0, "fwd"}, {1, "left"}};
  const double e = 1e-8;
  for (int c = 0; c < 2; ++c) {
    Mixture mix(m.dim());
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(m.dim());
    Eigen::MatrixXd cov = e * Eigen::MatrixXd::Identity(m.dim(), m.dim());
    if (c == 0) mean[0] = 0.1;
    if (c == 1) mean[2] = M_PI / 2;
    if (terrain) {  // z ~ N(0, 1); dx | z = mean + 0.5 z
      cov(3, 3) = 1;
      cov(0, 3) = cov(3, 0) = 0.5;
      cov(0, 0) += 0.25;
    }
    mix.Add(1.0, Gaussian(mean, cov));
    m.mixtures[c] = mix;
  }
  return m;
}

TEST(Predict, ComposesPoseChangesInTheRobotsFrame) {
  const MotionModel m = Planar(false);
  PredictOptions o;
  o.trajectories = 200;
  const Prediction p = Predict(m, Eigen::Vector3d(1, 2, 0), {{0, {}}, {1, {}}, {0, {}}}, o);
  ASSERT_EQ(p.steps.size(), 3u);
  EXPECT_FALSE(p.spatial);
  EXPECT_NEAR(p.steps[0].mean[0], 1.1, 1e-3);
  EXPECT_NEAR(p.steps[1].mean[3], M_PI / 2, 1e-3);
  // After the left turn, forward is +y.
  EXPECT_NEAR(p.steps[2].mean[0], 1.1, 1e-3);
  EXPECT_NEAR(p.steps[2].mean[1], 2.1, 1e-3);
  EXPECT_LT(p.steps[2].covariance.trace(), 1e-5);
}

TEST(Predict, ConditionsOnTheTerrainOfEachStep) {
  const MotionModel m = Planar(true);
  PredictOptions o;
  o.trajectories = 100;
  const Prediction p = Predict(m, Eigen::Vector3d::Zero(), {{0, Eigen::VectorXd::Constant(1, 0.2)}}, o);
  EXPECT_NEAR(p.steps[0].mean[0], 0.2, 1e-3);  // 0.1 + 0.5 * 0.2
  EXPECT_LT(p.steps[0].covariance(0, 0), 1e-6);
  const Prediction marginal = Predict(m, Eigen::Vector3d::Zero(), {{0, {}}}, o);
  EXPECT_GT(marginal.steps[0].covariance(0, 0), 0.1);  // the terrain's spread, marginalised
}

TEST(Predict, TheGroundConditionsEachTrajectoryWhereItStands) {
  // dx = 0.1 + 0.5 pitch: walking "uphill" (pitch < 0) is slower. On a plane tilted by 0.2 rad a
  // robot facing uphill (yaw 0) has pitch -0.2, facing downhill +0.2; after the quarter turn it
  // faces across the slope (pitch 0).
  MotionModel m = Planar(true);
  m.terrain_dim = 2;
  m.terrain_names = {"roll", "pitch"};  // by name, not by position
  for (auto& [c, mix] : m.mixtures) {
    Mixture grown(5);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Identity(5, 5);
    cov.topLeftCorner(4, 4) = mix.component(0).covariance();
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(5);
    mean.head(4) = mix.component(0).mean();
    // Terrain order (roll, pitch): the pitch column moves from 3 to 4.
    std::swap(cov(0, 3), cov(0, 4));
    std::swap(cov(3, 0), cov(4, 0));
    grown.Add(1.0, Gaussian(mean, cov));
    mix = grown;
  }
  PredictOptions o;
  o.trajectories = 100;
  o.ground = GroundTerrain(m, {0.2});
  const double pitch = std::asin(std::sin(0.2));
  const Prediction up = Predict(m, Eigen::Vector3d::Zero(), {{0, {}}, {1, {}}, {0, {}}}, o);
  EXPECT_NEAR(up.steps[0].mean[0], 0.1 - 0.5 * pitch, 1e-3);
  EXPECT_NEAR(up.steps[2].mean[1], 0.1, 1e-3);  // across the slope: pitch 0
  const Prediction down = Predict(m, Eigen::Vector3d(0, 0, M_PI), {{0, {}}}, o);
  EXPECT_NEAR(down.steps[0].mean[0], -(0.1 + 0.5 * pitch), 1e-3);
  const Eigen::VectorXd z = o.ground(Eigen::Vector4d(0, 0, 0, M_PI / 2));
  EXPECT_NEAR(z[1], 0, 1e-12);      // pitch facing across
  EXPECT_NEAR(z[0], -0.2, 1e-12);   // left side (downhill) down
}

TEST(Predict, AStandardisedModelIsReportedInRawUnits) {
  MotionModel m = Planar(true);
  m.transform.offset = Eigen::Vector4d(1.0, 0, 0, 0.5);
  m.transform.scale = Eigen::Vector4d(2.0, 1, 1, 4.0);
  PredictOptions o;
  o.trajectories = 100;
  // Raw pitch 0.5 is standardised 0: dx_std = 0.1, raw dx = 0.1 * 2 + 1.
  const Prediction p = Predict(m, Eigen::Vector3d::Zero(), {{0, Eigen::VectorXd::Constant(1, 0.5)}}, o);
  EXPECT_NEAR(p.steps[0].mean[0], 1.2, 1e-3);
}

TEST(Predict, SeededAndRepeatable) {
  const MotionModel m = Planar(true);
  PredictOptions o;
  o.trajectories = 50;
  const auto a = Predict(m, Eigen::Vector3d::Zero(), {{0, {}}, {1, {}}}, o);
  const auto b = Predict(m, Eigen::Vector3d::Zero(), {{0, {}}, {1, {}}}, o);
  EXPECT_EQ(a.steps[1].poses, b.steps[1].poses);
  o.seed = 2;
  EXPECT_NE(Predict(m, Eigen::Vector3d::Zero(), {{0, {}}, {1, {}}}, o).steps[1].poses, a.steps[1].poses);
}

TEST(Predict, BadInputIsRefusedNamingThePart) {
  const MotionModel m = Planar(true);
  PredictOptions o;
  EXPECT_THROW(Predict(m, Eigen::Vector3d::Zero(), {{7, {}}}, o), InputError);
  EXPECT_THROW(Predict(m, Eigen::Vector3d::Zero(), {{0, Eigen::VectorXd::Zero(3)}}, o), InputError);
  o.pose_dims = {"x", "y", "yaw"};
  EXPECT_THROW(Predict(m, Eigen::Vector3d::Zero(), {{0, {}}}, o), InputError);
  o.pose_dims.clear();
  o.trajectories = 0;
  EXPECT_THROW(Predict(m, Eigen::Vector3d::Zero(), {{0, {}}}, o), InputError);
}

}  // namespace
}  // namespace dgmm::predict
