// Ties: candidates of other families the data cannot tell apart from a named one.
#include "sim2real/ties.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/sim2real/toy_problem.h"

namespace dgmm::sim2real {
namespace {

// Two candidates with the same design (perfectly collinear signatures) from different families, or
// from one family at two scopes (the whole robot and one side), must be reported as a tie; a third,
// orthogonal one must not.
TEST(TiedCandidates, CollinearSignaturesTie) {
  const int n = 300, dx = 2;
  FitProblem fp = test::ToyProblem(n, dx);
  Eigen::MatrixXd d1(n * dx, 1), d3(n * dx, 1);
  for (int i = 0; i < n; ++i) {
    d1(i * dx) = 1.0 + 0.5 * std::sin(i);
    d1(i * dx + 1) = 0.3;
    d3(i * dx) = 0.0;
    d3(i * dx + 1) = std::cos(3.0 * i);
  }
  for (int k = 0; k < 3; ++k) {
    EffectSpec s;
    s.id = EffectId::kExternal;
    s.key = "e" + std::to_string(k);
    s.parameters = {{"t", ""}};
    fp.library.push_back(s);
  }
  fp.d = {d1, d1, d3};
  std::vector<int> fold;
  const std::vector<int> rows =
      test::FillResidualsAndFolds(&fp, [&](int i, int j) { return 0.8 * d1(i * dx + j); }, 3, &fold);
  SelectionOptions so;
  so.bootstrap_selection = 0;
  const SelectionResult sel = ForwardSelect(fp, rows, fold, so);
  ASSERT_FALSE(sel.selected.empty());
  const int chosen = sel.selected[0];
  ASSERT_NE(chosen, 2);
  std::vector<double> corr;
  const std::vector<int> tied =
      TiedCandidates(fp, sel.steps[0], chosen, {{"friction"}, {"payload"}, {"contact"}}, 0.9, so.fit, &corr);
  ASSERT_EQ(tied.size(), 1u);
  EXPECT_EQ(tied[0], chosen == 0 ? 1 : 0);
  EXPECT_NEAR(corr[0], 1.0, 1e-6);
  // The same family at the same scope is never a tie with itself: two whole-robot knobs, or two
  // sides (or legs) of it.
  EXPECT_TRUE(TiedCandidates(fp, sel.steps[0], chosen, {{"gain"}, {"gain"}, {"contact"}}, 0.9, so.fit).empty());
  EXPECT_TRUE(
      TiedCandidates(fp, sel.steps[0], chosen, {{"gain", false}, {"gain", false}, {"contact"}}, 0.9, so.fit).empty());
  // Every servo's gain against one side's: the same family at another scope ties.
  const std::vector<int> scoped =
      TiedCandidates(fp, sel.steps[0], chosen, {{"gain", chosen != 0}, {"gain", chosen == 0}, {"contact"}}, 0.9, so.fit);
  ASSERT_EQ(scoped.size(), 1u);
  EXPECT_EQ(scoped[0], chosen == 0 ? 1 : 0);
}

}  // namespace
}  // namespace dgmm::sim2real
