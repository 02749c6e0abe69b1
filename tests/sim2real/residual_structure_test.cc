// Structure in the corrected residual: step-periodic offsets are found, noise is not.
#include "sim2real/residual_structure.h"

#include <gtest/gtest.h>

#include <algorithm>
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

}  // namespace
}  // namespace dgmm::sim2real
