// Forward selection by held-out likelihood with the backward pass.
#include "sim2real/selection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tests/sim2real/toy_problem.h"

namespace dgmm::sim2real {
namespace {

using test::FillResidualsAndFolds;

// Two mean shifts, each too weak alone to beat a wider variance: forward selection takes noise
// first, then both shifts; the backward pass drops the noise again (the residual left by the two
// shifts has the simulated scale), and keeps both shifts.
TEST(ForwardSelect, BackwardPassDropsNoiseThatOnlyStoodInForMissingShifts) {
  const int n = 400, dx = 2;
  FitProblem fp = test::ToyProblem(n, dx);
  Eigen::MatrixXd d1 = Eigen::MatrixXd::Zero(n * dx, 1), d2 = Eigen::MatrixXd::Zero(n * dx, 1);
  for (int i = 0; i < n; ++i) {
    d1(i * dx) = (i % 2 ? 1.0 : -1.0);
    d2(i * dx + 1) = ((i / 2) % 2 ? 1.0 : -1.0);
  }
  EffectSpec noise;
  noise.id = EffectId::kNoise;
  noise.key = "noise";
  noise.is_noise = true;
  noise.parameters = {{"log_tau", ""}};
  fp.library.push_back(noise);
  for (int k = 1; k <= 2; ++k) {
    EffectSpec s;
    s.id = EffectId::kExternal;
    s.key = "e" + std::to_string(k);
    s.parameters = {{"t", ""}};
    fp.library.push_back(s);
  }
  fp.d = {Eigen::MatrixXd::Zero(n * dx, 1), d1, d2};
  std::vector<int> fold;
  const std::vector<int> rows = FillResidualsAndFolds(
      &fp, [&](int i, int j) { return 2.5 * d1(i * dx + j) + 2.5 * d2(i * dx + j); }, 5, &fold);
  SelectionOptions so;
  so.bootstrap_selection = 0;
  const SelectionResult forward = ForwardSelect(fp, rows, fold, so);
  ASSERT_FALSE(forward.steps.empty());
  ASSERT_EQ(forward.steps[0].chosen, 0) << "the case needs noise to win the first step";
  EXPECT_EQ(forward.selected.size(), 3u);
  so.backward = true;
  const SelectionResult both = ForwardSelect(fp, rows, fold, so);
  EXPECT_EQ(both.removed, std::vector<int>{0});
  std::vector<int> kept = both.selected;
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, (std::vector<int>{1, 2}));
  EXPECT_NEAR(both.fit.log_tau, 0.0, 0.15);
  EXPECT_GE(both.heldout_corrected.mean(), forward.heldout_corrected.mean() - 0.01);
}

}  // namespace
}  // namespace dgmm::sim2real
