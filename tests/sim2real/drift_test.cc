#include "sim2real/drift.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace dgmm::sim2real {
namespace {

// A session of `commands` x `per_command` episodes of `steps` samples (dx 3). The effect's shift
// is a fixed vector per command; the residual is N(0, I) plus gamma (t - 1/2) times the shift,
// t the episode's position in [0, 1]. `blocked`: each command's episodes are consecutive (the
// paper protocol); otherwise the commands are interleaved.
struct Session {
  Eigen::MatrixXd residual, shift;
  std::vector<int> command, episode;
};

Session MakeSession(double gamma, bool blocked, std::uint64_t seed, int commands = 20, int per_command = 3,
                    int steps = 5) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> v(commands);
  for (auto& x : v) x = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 0.5;
  std::vector<int> order(commands);
  for (int c = 0; c < commands; ++c) order[c] = c;
  std::shuffle(order.begin(), order.end(), rng);
  const int episodes = commands * per_command, n = episodes * steps;
  Session s;
  s.residual.resize(n, 3);
  s.shift.resize(n, 3);
  for (int e = 0; e < episodes; ++e) {
    const int c = blocked ? order[e / per_command] : order[e % commands];
    const double t = static_cast<double>(e) / (episodes - 1);
    for (int k = 0; k < steps; ++k) {
      const int i = e * steps + k;
      s.command.push_back(c);
      s.episode.push_back(e);
      s.shift.row(i) = v[c].transpose();
      s.residual.row(i) = Eigen::RowVector3d(normal(rng), normal(rng), normal(rng)) + gamma * (t - 0.5) * v[c].transpose();
    }
  }
  return s;
}

// One effect: the whole correction is that effect.
EffectDrift Mark(const EffectDrift& d, const DriftOptions& options) {
  EffectDrift total = d;
  std::vector<EffectDrift> one = {d};
  MarkDrifting(&total, &one, options);
  EXPECT_EQ(total.drifting, one[0].drifting);
  return one[0];
}

TEST(EffectDrift, FindsADriftWhetherCommandsAreRecordedInBlocksOrInterleaved) {
  DriftOptions options;
  for (const bool blocked : {true, false}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const Session s = MakeSession(2.0, blocked, seed);
      const EffectDrift d = Mark(TestEffectDrift(s.residual, s.shift, s.command, s.episode, options, seed), options);
      EXPECT_TRUE(d.drifting) << "blocked " << blocked << " seed " << seed << " p " << d.p_value;
      EXPECT_NEAR(d.gamma, 2.0, 0.6) << "blocked " << blocked << " seed " << seed;
      EXPECT_GT(d.z, 2.5);
      EXPECT_EQ(d.episodes, 60);
    }
  }
}

TEST(EffectDrift, AConstantEffectIsRarelyCalledDrifting) {
  DriftOptions options;
  options.permutations = 200;
  int drifting = 0, small_p = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Session s = MakeSession(0.0, seed % 2 == 0, 100 + seed);
    const EffectDrift d = Mark(TestEffectDrift(s.residual, s.shift, s.command, s.episode, options, seed), options);
    drifting += d.drifting;
    small_p += d.p_value < 0.05;
  }
  EXPECT_EQ(drifting, 0);
  EXPECT_LE(small_p, 7);  // a valid test: about 5% of 40 below 0.05
}

TEST(EffectDrift, ASignificantButSmallChangeIsNotADrift) {
  DriftOptions options;
  // Much data, a 20% change over the session: significant, below min_relative_change (0.5).
  const Session s = MakeSession(0.2, true, 7, 40, 6, 20);
  const EffectDrift d = Mark(TestEffectDrift(s.residual, s.shift, s.command, s.episode, options, 7), options);
  EXPECT_LT(d.p_value, 0.01);
  EXPECT_LT(std::abs(d.gamma), 0.5);
  EXPECT_FALSE(d.drifting);
}

TEST(EffectDrift, NoEpisodesToCompareOrNoShiftIsNoDrift) {
  DriftOptions options;
  const Session s = MakeSession(2.0, true, 3);
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(s.shift.rows(), 3);
  EffectDrift none = TestEffectDrift(s.residual, zero, s.command, s.episode, options, 1);
  EXPECT_EQ(none.gamma, 0.0);
  EXPECT_EQ(none.p_value, 1.0);
  const std::vector<int> one_episode(s.episode.size(), 4);
  EffectDrift single = TestEffectDrift(s.residual, s.shift, s.command, one_episode, options, 1);
  EXPECT_EQ(single.p_value, 1.0);
  EXPECT_EQ(single.episodes, 1);
}

// Episodes of `steps` samples; a constant shift per episode; the residual is N(0, I) plus
// `amplitude` sin(2 pi step / 3) times the shift (the effect's size varies with the step).
Session MakeStepSession(double amplitude, std::uint64_t seed, std::vector<int>* step, int episodes = 60,
                        int steps = 5) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Session s;
  s.residual.resize(episodes * steps, 3);
  s.shift.resize(episodes * steps, 3);
  step->clear();
  for (int e = 0; e < episodes; ++e) {
    const Eigen::RowVector3d v(normal(rng) * 0.5, normal(rng) * 0.5, 0.5);
    for (int k = 0; k < steps; ++k) {
      const int i = e * steps + k;
      s.command.push_back(e % 20);
      s.episode.push_back(e);
      step->push_back(k);
      s.shift.row(i) = v;
      s.residual.row(i) = Eigen::RowVector3d(normal(rng), normal(rng), normal(rng)) +
                          amplitude * std::sin(2 * M_PI * k / 3.0) * v;
    }
  }
  return s;
}

TEST(EffectStepVariation, FindsAnEffectWhoseSizeFollowsTheExecutionIndex) {
  DriftOptions options;
  std::vector<int> step;
  const Session s = MakeStepSession(2.0, 5, &step);
  EffectDrift v = TestEffectStepVariation(s.residual, s.shift, s.episode, step, options, 1);
  EffectDrift total = v;
  std::vector<EffectDrift> one = {v};
  MarkDrifting(&total, &one, options);
  EXPECT_TRUE(one[0].drifting) << "p " << v.p_value << " gamma " << v.gamma;
  EXPECT_GT(v.gamma, 0.8);  // RMS of 2 sin(2 pi k / 3) over k = 0..4 is about 1.5
  EXPECT_LT(v.low, 0.0);    // 1 - 2 sin(60 deg) = -0.73 at step 2 (or 5)
  EXPECT_GT(v.high, 2.0);   // 1 + 1.73 at step 1 or 4
  EXPECT_TRUE(v.low_step == 2 || v.low_step == 5);
  EXPECT_TRUE(v.high_step == 1 || v.high_step == 4);
}

TEST(EffectStepVariation, AConstantEffectIsRarelyCalledVarying) {
  DriftOptions options;
  options.permutations = 200;
  int varies = 0;
  std::vector<int> step;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    const Session s = MakeStepSession(0.0, 200 + seed, &step);
    EffectDrift v = TestEffectStepVariation(s.residual, s.shift, s.episode, step, options, seed);
    EffectDrift total = v;
    std::vector<EffectDrift> one = {v};
    MarkDrifting(&total, &one, options);
    varies += one[0].drifting;
    EXPECT_LT(v.gamma, 0.5) << "seed " << seed;
  }
  EXPECT_EQ(varies, 0);
  const std::vector<int> no_steps(step.size(), -1);
  const Session s = MakeStepSession(2.0, 5, &step);
  EXPECT_EQ(TestEffectStepVariation(s.residual, s.shift, s.episode, no_steps, options, 1).p_value, 1.0);
}

TEST(EffectDrift, AnEffectDriftsOnlyWhenTheWholeCorrectionDoes) {
  DriftOptions options;  // alpha 0.01
  std::vector<EffectDrift> d(4);
  for (auto& e : d) e.gamma = 1.0;
  d[0].p_value = 0.001;  // < 0.01 / 4
  d[1].p_value = 0.004;  // < 0.01, not < 0.0025
  d[2].p_value = 0.001, d[2].gamma = -0.3;  // significant but small
  d[3].p_value = 0.5;
  EffectDrift total;
  total.gamma = 1.5, total.p_value = 0.001;
  MarkDrifting(&total, &d, options);
  EXPECT_TRUE(total.drifting);
  EXPECT_TRUE(d[0].drifting);
  EXPECT_FALSE(d[1].drifting);
  EXPECT_FALSE(d[2].drifting);
  EXPECT_FALSE(d[3].drifting);
  // The same effect tests, but the correction as a whole is constant (two correlated effects
  // sharing a constant mismatch differently over the session): no effect drifts.
  total.p_value = 0.2;
  MarkDrifting(&total, &d, options);
  EXPECT_FALSE(total.drifting);
  EXPECT_FALSE(d[0].drifting);
  total.p_value = 0.001, total.gamma = 0.3;  // significant, too small
  MarkDrifting(&total, &d, options);
  EXPECT_FALSE(d[0].drifting);
  std::string error;
  options.permutations = 5;
  EXPECT_FALSE(options.IsValid(&error));
}

}  // namespace
}  // namespace dgmm::sim2real
