// Structure in the corrected residual: step-periodic offsets are found, noise is not.
#include "sim2real/residual_structure.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>


namespace dgmm::sim2real {
namespace {

// Residuals with a step-periodic offset (alternating sign along the five executions of each
// placement) are structured, in "step" and "periodic"; plain Gaussian residuals are not.
TEST(ResidualStructure, PeriodicStepOffsetIsStructuredNoiseIsNot) {
  const int episodes = 78, n = 5 * episodes, dx = 3;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd r(n, dx);
  std::vector<int> command(n), terrain(n), episode(n), step(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < dx; ++j) r(i, j) = unit(rng);
    episode[i] = i / 5;
    step[i] = i % 5;
    command[i] = (i / 5) % 26;
    terrain[i] = (i / 5) % 3;
  }
  ResidualStructureOptions options;
  const ResidualStructure clean = TestResidualStructure(r, command, terrain, episode, step, ExcessKurtosis(r), options, 1);
  EXPECT_TRUE(clean.structured_in.empty());
  for (int i = 0; i < n; ++i) r(i, 1) += (step[i] % 2 == 0 ? 0.6 : -0.6);
  const ResidualStructure periodic = TestResidualStructure(r, command, terrain, episode, step, 0.0, options, 1);
  auto has = [&](const std::string& w) {
    return std::find(periodic.structured_in.begin(), periodic.structured_in.end(), w) != periodic.structured_in.end();
  };
  EXPECT_TRUE(has("step"));
  EXPECT_TRUE(has("periodic"));
  EXPECT_FALSE(has("command"));
}

// Rough ground: a few placements hang up on a boulder and all their executions come out far off.
// Two draws of placements (a null pair) differ in kurtosis by chance far more than the sample-count
// SE allows; counted in placements (the placement bootstrap) the difference is not significant.
// `hung` of `episodes` placements hang up; every row is unit noise plus its placement's offset.
Eigen::MatrixXd HangUps(int episodes, int hung, std::mt19937_64& rng, std::vector<int>* episode) {
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd r(5 * episodes, 3);
  episode->resize(5 * episodes);
  for (int e = 0; e < episodes; ++e) {
    const double offset = e < hung ? 6.0 * unit(rng) : 0.0;
    for (int s = 0; s < 5; ++s) {
      for (int j = 0; j < 3; ++j) r(5 * e + s, j) = unit(rng) + offset;
      (*episode)[5 * e + s] = e;
    }
  }
  return r;
}

TEST(ResidualStructure, TailsAreCountedInPlacementsWhenTheyHangUpTogether) {
  std::mt19937_64 rng(8);
  std::vector<int> sim_episode, real_episode;
  const Eigen::MatrixXd sim = HangUps(166, 3, rng, &sim_episode);
  const Eigen::MatrixXd real = HangUps(166, 7, rng, &real_episode);
  const int n = static_cast<int>(real.rows());
  std::vector<int> command(n), terrain(n, -1), step(n, -1);
  for (int i = 0; i < n; ++i) command[i] = (i / 5) % 26;
  auto tails = [&](const ResidualStructure& s) {
    return std::find(s.structured_in.begin(), s.structured_in.end(), "tails") != s.structured_in.end();
  };
  ResidualStructureOptions by_samples;
  EXPECT_TRUE(tails(TestResidualStructure(real, command, terrain, real_episode, step, ExcessKurtosis(sim), by_samples, 1)));
  ResidualStructureOptions by_placements;
  by_placements.tails_bootstrap = 200;
  const double sim_se = ExcessKurtosisSe(sim, sim_episode, 200, 3);
  EXPECT_GT(sim_se, 1.0);
  EXPECT_FALSE(tails(
      TestResidualStructure(real, command, terrain, real_episode, step, ExcessKurtosis(sim), by_placements, 1, sim_se)));
  // Heavy tails in every placement's executions (not a few placements) are still found: a
  // contaminated normal, 1 in 10 executions with 3 times the spread (excess kurtosis 5.3).
  Eigen::MatrixXd heavy = HangUps(166, 0, rng, &real_episode);
  std::bernoulli_distribution wide(0.1);
  for (int i = 0; i < n; ++i) {
    if (wide(rng)) heavy.row(i) *= 3.0;
  }
  const double flat_se = ExcessKurtosisSe(HangUps(166, 0, rng, &sim_episode), sim_episode, 200, 4);
  EXPECT_TRUE(tails(TestResidualStructure(heavy, command, terrain, real_episode, step, 0.0, by_placements, 1, flat_se)));
}

// Unit-noise residuals of `episodes` placements of five executions, each execution offset by
// `profile` (its step's offset on column 1).
Eigen::MatrixXd StepProfiled(int episodes, const std::vector<double>& profile, std::mt19937_64& rng,
                             std::vector<int>* episode, std::vector<int>* step) {
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd r(5 * episodes, 3);
  episode->resize(r.rows());
  step->resize(r.rows());
  for (int i = 0; i < r.rows(); ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = unit(rng);
    (*episode)[i] = i / 5;
    (*step)[i] = i % 5;
    r(i, 1) += profile[i % 5];
  }
  return r;
}

// A step profile that the model leaves in the sim set's own residuals as much as in the real set's
// (a robot whose executions drift the same way in both, which the model's first-execution term does
// not describe) is no mismatch: against the sim set's profile it is not structure; a real profile
// that differs from the sim set's still is. Planar quadruped null pairs 59005 and 59007 came out
// `unexplained` in "step" when the test asked whether the real profile differed from none.
TEST(ResidualStructure, AStepProfileTheSimSetSharesIsNotStructure) {
  std::mt19937_64 rng(11);
  const std::vector<double> shared = {0.0, 0.35, 0.2, 0.05, -0.1};
  std::vector<int> sim_episode, sim_step, real_episode, real_step;
  const Eigen::MatrixXd sim = StepProfiled(166, shared, rng, &sim_episode, &sim_step);
  const Eigen::MatrixXd real = StepProfiled(78, shared, rng, &real_episode, &real_step);
  const int n = static_cast<int>(real.rows());
  std::vector<int> command(n), terrain(n, -1);
  for (int i = 0; i < n; ++i) command[i] = (i / 5) % 26;
  auto step = [&](const ResidualStructure& s) {
    return std::find(s.structured_in.begin(), s.structured_in.end(), "step") != s.structured_in.end();
  };
  const ResidualStructureOptions options;
  const double no_tails = NAN;
  EXPECT_TRUE(step(TestResidualStructure(real, command, terrain, real_episode, real_step, no_tails, options, 1)));
  const SimReference reference{&sim, &sim_episode, &sim_step};
  EXPECT_FALSE(step(TestResidualStructure(real, command, terrain, real_episode, real_step, no_tails, options, 1, 0,
                                          reference)));
  // A sim set without execution indices gives no profile: the one-set test.
  const std::vector<int> no_steps(sim_step.size(), -1);
  EXPECT_TRUE(step(TestResidualStructure(real, command, terrain, real_episode, real_step, no_tails, options, 1, 0,
                                         {&sim, &sim_episode, &no_steps})));
  const Eigen::MatrixXd other = StepProfiled(78, {0.0, -0.2, 0.3, -0.2, 0.3}, rng, &real_episode, &real_step);
  EXPECT_TRUE(step(TestResidualStructure(other, command, terrain, real_episode, real_step, no_tails, options, 1, 0,
                                         reference)));
}

// Unit-noise residuals of `episodes` placements of five executions, command (episode mod 12),
// offset on column 0 by `offset` times the command's id mod 3 minus 1 (the model's misfit per command).
Eigen::MatrixXd CommandOffsets(int episodes, double offset, std::mt19937_64& rng, std::vector<int>* episode,
                               std::vector<int>* command) {
  std::vector<int> step;
  Eigen::MatrixXd r = StepProfiled(episodes, {0, 0, 0, 0, 0}, rng, episode, &step);
  command->resize(r.rows());
  for (int i = 0; i < r.rows(); ++i) {
    (*command)[i] = (i / 5) % 12;
    r(i, 0) += offset * ((*command)[i] % 3 - 1);
  }
  return r;
}

// Command means the model misses in the sim set's own residuals as much as in the real set's are no
// mismatch: against the sim set's they are not structure, a real offset of its own still is. Every
// pair on record had "command" at p 0.001 when the test asked whether the real means differed
// from none, `explained` ones too.
TEST(ResidualStructure, CommandMeansTheSimSetSharesAreNotStructure) {
  std::mt19937_64 rng(12);
  std::vector<int> sim_episode, sim_command, real_episode, real_command;
  const Eigen::MatrixXd sim = CommandOffsets(166, 0.5, rng, &sim_episode, &sim_command);
  const Eigen::MatrixXd shared = CommandOffsets(78, 0.5, rng, &real_episode, &real_command);
  const Eigen::MatrixXd own = CommandOffsets(78, 0.9, rng, &real_episode, &real_command);
  const std::vector<int> terrain(shared.rows(), -1), step(shared.rows(), -1);
  auto command = [&](const ResidualStructure& s) {
    return std::find(s.structured_in.begin(), s.structured_in.end(), "command") != s.structured_in.end();
  };
  const ResidualStructureOptions options;
  const double no_tails = NAN;
  EXPECT_TRUE(command(TestResidualStructure(shared, real_command, terrain, real_episode, step, no_tails, options, 1)))
      << "against none, the shared offsets are structure";
  SimReference reference;
  reference.residuals = &sim, reference.episode = &sim_episode, reference.command = &sim_command;
  EXPECT_FALSE(command(
      TestResidualStructure(shared, real_command, terrain, real_episode, step, no_tails, options, 1, 0, reference)));
  EXPECT_TRUE(command(
      TestResidualStructure(own, real_command, terrain, real_episode, step, no_tails, options, 1, 0, reference)))
      << "offsets larger than the sim set's";
}

}  // namespace
}  // namespace dgmm::sim2real
