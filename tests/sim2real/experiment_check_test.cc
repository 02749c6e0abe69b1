// The check by simulation of a tie's discriminating experiment: the separation statistics of
// paired outcome sets, and the simulated cell itself (two knobs with clearly different effects
// are confirmed separable, two knobs with the same effect are not).
#include "sim2real/experiment_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "tests/sim2real/fake_simulator.h"
#include "sim2real/verdict.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

Eigen::MatrixXd Gaussian(int n, int d, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd m(n, d);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < d; ++j) m(i, j) = unit(rng);
  return m;
}

TEST(SeparationOfPairs, MeasuresAShiftAndNotItsAbsence) {
  const int n = 400, d = 3;
  // Outcomes with unit spread per dimension (scaled to mixed units: the whitening must not care).
  Eigen::MatrixXd a = Gaussian(n, d, 1);
  a.col(0) *= 0.01;  // metres
  a.col(2) *= 0.2;   // radians
  // b: the same executions (common random numbers) shifted by 1 sd in dimension 0, plus a small
  // independent part.
  Eigen::MatrixXd b = a + 0.1 * Gaussian(n, d, 2).cwiseProduct(Eigen::RowVector3d(0.01, 1, 0.2).replicate(n, 1));
  b.col(0).array() += 0.01;
  const PairedSeparation shifted = SeparationOfPairs(a, b, 12, 999, 7);
  EXPECT_EQ(shifted.pairs, n);
  EXPECT_NEAR(shifted.d2, 1.0, 0.25);  // true squared whitened distance 1 (sample spread varies)
  EXPECT_NEAR(shifted.z, std::sqrt(12 * shifted.d2), 1e-12);
  EXPECT_LT(shifted.p_value, 0.005);
  EXPECT_NEAR(shifted.executions_needed, std::ceil(11.7 / shifted.d2), 0.5);

  // A real spread twice the simulated one: a quarter of the squared separation (the estimation
  // bias correction does not scale, so only approximately).
  EXPECT_NEAR(SeparationOfPairs(a, b, 12, 99, 7, 2.0).d2, shifted.d2 / 4, 0.02);
  EXPECT_THROW(SeparationOfPairs(a, b, 12, 99, 7, 0.0), InputError);

  // Identical outcomes (same physics, same random numbers): nothing measured.
  const PairedSeparation same = SeparationOfPairs(a, a, 12, 999, 7);
  EXPECT_EQ(same.d2, 0.0);
  EXPECT_EQ(same.z, 0.0);
  EXPECT_EQ(same.p_value, 1.0);
  EXPECT_EQ(same.executions_needed, -1);

  // A zero-mean paired difference (chaotic divergence only): the debiased separation is about 0.
  const Eigen::MatrixXd c = a + 0.3 * Gaussian(n, d, 3).cwiseProduct(Eigen::RowVector3d(0.01, 1, 0.2).replicate(n, 1));
  const PairedSeparation noise = SeparationOfPairs(a, c, 12, 999, 7);
  EXPECT_LT(noise.d2, 0.05);
  EXPECT_GT(noise.p_value, 0.005);

  // Same seed, same result.
  EXPECT_EQ(SeparationOfPairs(a, b, 12, 999, 7).p_value, shifted.p_value);
  EXPECT_THROW(SeparationOfPairs(a.topRows(4), b.topRows(4), 12, 99, 1), InputError);
  EXPECT_THROW(SeparationOfPairs(a, b.leftCols(2), 12, 99, 1), InputError);
}

TEST(CheckExperiment, ConfirmsClearlyDifferentKnobsAndNotIdenticalOnes) {
  const test::FakeSimulator fake;
  ExperimentCheckOptions options;
  options.seed = 11;
  options.min_executions = 15;
  options.permutations = 500;
  const Eigen::Vector3d forward(0.5, 0, 0);
  const Eigen::Vector2d downhill(0.3, 0.0);
  const KnobValue slippery{test::kFriction, 0.3};
  const KnobValue weak_left{test::kLeftGain, 0.3};
  const ExperimentCheck differ = CheckExperiment(fake, slippery, weak_left, forward, downhill, 10, options);
  ASSERT_TRUE(differ.checked) << differ.why_not;
  EXPECT_EQ(differ.executions_simulated, 15);
  EXPECT_EQ(differ.placements, 3);
  EXPECT_EQ(fake.cells(), 2);  // one recording per knob value
  EXPECT_GT(differ.separation.d2, 11.7 / 10);  // separable within the proposed 10 executions
  EXPECT_TRUE(differ.confirmed) << "z " << differ.separation.z << " p " << differ.separation.p_value;

  // Two different knobs that change nothing (each at its nominal value): identical physics.
  const ExperimentCheck same = CheckExperiment(fake, {test::kFriction, 1.0}, {test::kLeftGain, 1.0}, forward, downhill,
                                               10, options);
  ASSERT_TRUE(same.checked) << same.why_not;
  EXPECT_EQ(same.separation.d2, 0.0);
  EXPECT_FALSE(same.confirmed);
  EXPECT_EQ(same.separation.executions_needed, -1);
}

TEST(Verdict, ExperimentCheckFieldsInTheJson) {
  Verdict v;
  v.status = "explained";
  VerdictTie tie;
  tie.families = {"joint_damping", "friction"};
  tie.experiment.commands = {"0,+0.5,0"};
  tie.experiment.terrain = {"across"};
  tie.experiment.executions = 9;
  tie.experiment.not_checked_because = "x";
  v.ties.push_back(tie);
  tie.experiment.checked_by_simulation = true;
  tie.experiment.confirmed = false;
  tie.experiment.executions_needed = 40;
  tie.experiment.seed = 5;
  v.ties.push_back(tie);
  const auto j = nlohmann::json::parse(VerdictJson(v));
  const auto& unchecked = j["ties"][0]["experiment"];
  EXPECT_FALSE(unchecked["checked_by_simulation"].get<bool>());
  EXPECT_TRUE(unchecked["confirmed"].is_null());
  EXPECT_TRUE(unchecked["simulation"].is_null());
  EXPECT_EQ(unchecked["not_checked_because"], "x");
  const auto& checked = j["ties"][1]["experiment"];
  EXPECT_TRUE(checked["checked_by_simulation"].get<bool>());
  EXPECT_FALSE(checked["confirmed"].get<bool>());
  EXPECT_EQ(checked["simulation"]["executions_needed"], 40);
  EXPECT_EQ(checked["simulation"]["seed"], 5);
  EXPECT_EQ(checked["executions"], 9);  // the agreed fields stay
  // The conclusion never claims more than measured.
  EXPECT_NE(DescribeExperiment(v.ties[0].experiment).find("not checked by simulation: x"), std::string::npos);
  const std::string refuted = DescribeExperiment(v.ties[1].experiment);
  EXPECT_NE(refuted.find("would not separate them"), std::string::npos);
  EXPECT_NE(refuted.find("more executions needed: 40"), std::string::npos);
  v.ties[1].experiment.confirmed = true;
  EXPECT_NE(DescribeExperiment(v.ties[1].experiment).find("separates them"), std::string::npos);
  v.ties[1].experiment.confirmed = false;
  v.ties[1].experiment.executions_needed = -1;
  EXPECT_NE(DescribeExperiment(v.ties[1].experiment).find("no measurable difference"), std::string::npos);
}

}  // namespace
}  // namespace dgmm::sim2real
