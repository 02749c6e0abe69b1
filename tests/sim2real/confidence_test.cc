// Stage 5: inclusion per candidate, per family and per family at a scope in [0, 1], the value's interval around it.
#include "sim2real/confidence.h"

#include <gtest/gtest.h>

#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

TEST(Confidence, FamilyInclusionCoversItsCandidatesAndTheValueItsInterval) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.6}}, 5);
  const Confidence& c = s.confidence;
  ASSERT_TRUE(c.computed);
  EXPECT_EQ(c.resamples, s.options.refine.selection.bootstrap_selection);
  for (double v : c.inclusion) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
  }
  for (size_t k = 0; k < s.set.candidates.size(); ++k) {
    EXPECT_GE(c.family_inclusion.at(s.set.candidates[k].family) + 1e-12, c.inclusion[k]) << s.set.candidates[k].key;
    // Its family at its scope (the whole robot, or a side or leg) lies between the two.
    EXPECT_GE(c.scope_inclusion[k] + 1e-12, c.inclusion[k]) << s.set.candidates[k].key;
    EXPECT_GE(c.family_inclusion.at(s.set.candidates[k].family) + 1e-12, c.scope_inclusion[k]) << s.set.candidates[k].key;
  }
  EXPECT_GE(c.family_inclusion.at("friction"), 0.8);
  ASSERT_EQ(c.value_lower.size(), s.refinement.selection.selected.size());
  const int k = test::CandidateOf(s.set, "floor.friction@0.6");
  const size_t pos = std::find(s.refinement.selection.selected.begin(), s.refinement.selection.selected.end(), k) -
                     s.refinement.selection.selected.begin();
  ASSERT_LT(pos, c.value_lower.size());
  const double value = CandidateValue(s.set, s.refinement, k, s.refinement.selection.fit.theta[pos]);
  EXPECT_LE(c.value_lower[pos], value);
  EXPECT_GE(c.value_upper[pos], value);
}

TEST(Confidence, BootstrapOffIsNotComputed) {
  test::Stages s = test::RunStages({{test::kFriction, 0.6}}, 4);
  s.refinement.selection_options.bootstrap_selection = 0;
  std::mt19937_64 rng(1);
  const Confidence c = AssessConfidence(s.set, s.refinement, rng);
  EXPECT_FALSE(c.computed);
  for (double v : c.inclusion) EXPECT_LT(v, 0.0);
}

}  // namespace
}  // namespace dgmm::sim2real
