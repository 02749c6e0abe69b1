#include "sim/gait.h"

#include <gtest/gtest.h>

#include <random>

namespace dgmm::sim {
namespace {

constexpr double kTolM = 1e-9;  // IK is closed form: exact up to round-off

LegGeometry LeftLeg() {
  LegGeometry leg;
  leg.hip_m = {0.075, 0.15, 0};
  leg.outward_rad = M_PI / 2;
  return leg;
}

TEST(GaitTest, InverseKinematicsInvertsForwardKinematics) {
  std::mt19937_64 rng(0);
  std::uniform_real_distribution<double> yaw(-0.8, 0.8), pitch(-0.6, 0.8), knee(-0.6, 0.9);
  for (LegGeometry leg : {LeftLeg(), [] { LegGeometry r = LeftLeg(); r.outward_rad = -M_PI / 2; r.coxa_up_m = 0.01; return r; }()}) {
    for (int i = 0; i < 200; ++i) {
      const LegAngles q(yaw(rng), pitch(rng), knee(rng));
      const Eigen::Vector3d foot = LegForward(leg, q);
      const Eigen::Vector3d back = LegForward(leg, LegInverse(leg, foot));
      EXPECT_LT((back - foot).norm(), kTolM) << q.transpose();
    }
  }
}

TEST(GaitTest, KneeStaysAboveTheFoot) {
  const LegGeometry leg = LeftLeg();
  GaitConfig gait;
  const LegAngles q = LegInverse(leg, NominalFoot(leg, gait));
  EXPECT_GT(q[1], 0);  // femur raised: the knee is above the hip-pitch axis
  EXPECT_NEAR(LegForward(leg, q).z(), -(gait.stance_height_m - leg.foot_radius_m), kTolM);
}

TEST(GaitTest, PatternStartsAndEndsAtTheNominalStance) {
  const LegGeometry leg = LeftLeg();
  GaitConfig gait;
  const Eigen::Vector3d c(0.5, -0.5, 0.5);
  for (int i = 0; i < kNumLegs; ++i) {
    EXPECT_LT((FootTarget(leg, i, c, 1e-9, 1.5, gait) - NominalFoot(leg, gait)).norm(), 1e-6);
    EXPECT_LT((FootTarget(leg, i, c, 1.5 - 1e-9, 1.5, gait) - NominalFoot(leg, gait)).norm(), 1e-6);
  }
}

TEST(GaitTest, StanceFeetMoveAgainstTheCommand) {
  const LegGeometry leg = LeftLeg();
  GaitConfig gait;
  // Tetrapod A (leg 0) is in stance during the first quarter period: its foot moves backwards
  // for a forward command and stays on the ground; tetrapod B (leg 1) is lifted then.
  const double t0 = 0.01, t1 = 0.2 * gait.period_s;
  const Eigen::Vector3d a0 = FootTarget(leg, 0, {1, 0, 0}, t0, 1.5, gait);
  const Eigen::Vector3d a1 = FootTarget(leg, 0, {1, 0, 0}, t1, 1.5, gait);
  EXPECT_LT(a1.x(), a0.x());
  EXPECT_NEAR(a1.z(), NominalFoot(leg, gait).z(), kTolM);
  EXPECT_GT(FootTarget(leg, 1, {1, 0, 0}, 0.125 * gait.period_s, 1.5, gait).z(),
            NominalFoot(leg, gait).z() + 0.5 * gait.step_height_m);
  // Exactly one tetrapod per leg, four legs each.
  int a = 0;
  for (int i = 0; i < kNumLegs; ++i) a += InTetrapodA(i);
  EXPECT_EQ(a, 4);
}

TEST(GaitTest, NoOpCommandOnlyLiftsFeet) {
  const LegGeometry leg = LeftLeg();
  GaitConfig gait;
  for (double t = 0; t < 1.5; t += 0.01) {
    const Eigen::Vector3d f = FootTarget(leg, 3, Eigen::Vector3d::Zero(), t, 1.5, gait);
    EXPECT_LT((f - NominalFoot(leg, gait)).head<2>().norm(), kTolM);
  }
}

}  // namespace
}  // namespace dgmm::sim
