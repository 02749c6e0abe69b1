// Stage 4: selection and refinement by re-recording. The fake's friction is non-linear, so the
// probe's linear extrapolation is off and the likelihood search must find the value.
#include "sim2real/refine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

// The value the selected friction stands for, and the refinement of it.
double NamedFriction(const test::Stages& s, const std::string& key) {
  const Refinement& r = s.refinement;
  const int k = test::CandidateOf(s.set, key);
  const auto pos = std::find(r.selection.selected.begin(), r.selection.selected.end(), k);
  if (pos == r.selection.selected.end()) return NAN;
  return CandidateValue(s.set, r, k, r.selection.fit.theta[pos - r.selection.selected.begin()]);
}

TEST(Refine, FrictionIsFoundByALikelihoodSearchOverItsValue) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.45}}, 4);
  const Refinement& r = s.refinement;
  ASSERT_FALSE(r.refined.empty());
  EXPECT_EQ(r.refined[0].knob, "floor.friction");
  EXPECT_TRUE(r.refined[0].converged) << "the search brackets its best value";
  EXPECT_TRUE(r.refined[0].recorded);
  int scored = 0;
  for (const auto& t : r.trace) scored += t.knob == "floor.friction" && std::isfinite(t.score);
  EXPECT_GE(scored, 4) << "the probe and a grid of three, each scored";
  const int k = test::CandidateOf(s.set, "floor.friction@0.6");
  EXPECT_EQ(r.signature_at[k], r.refined[0].value);
  EXPECT_TRUE(r.searched[k]);
  // The value the signature stands for is the planted one (the fake is exact up to noise).
  EXPECT_NEAR(NamedFriction(s, "floor.friction@0.6"), 0.45, 0.05);
  // The values that fit as well as the best: the best among them, no more than were scored.
  const SearchSpan& a = r.refined[0].as_well;
  ASSERT_TRUE(a.Searched());
  EXPECT_LE(a.lower, r.refined[0].value);
  EXPECT_GE(a.upper, r.refined[0].value);
  EXPECT_LE(a.points, a.searched);
  EXPECT_EQ(a.searched, scored);
  EXPECT_TRUE(std::isnan(a.x_lower)) << "a forward offset only for the payload";
}

TEST(Refine, AFrictionThatOnlySlipsBelowAThresholdIsFoundWhereTheLinearReadingIsFlat) {
  // Probed at 0.35 below a threshold of 0.6, planted at 0.45: the linear reading (about 0.61) lies
  // where friction changes nothing, so no coefficient there can say how far to go.
  const test::FakeSimulator fake(0.6, {0.35});
  const test::Stages s = test::RunStages(fake, {{test::kFriction, 0.45}}, 4);
  ASSERT_FALSE(s.refinement.refined.empty());
  EXPECT_TRUE(s.refinement.refined[0].converged);
  EXPECT_NEAR(NamedFriction(s, "floor.friction@0.35"), 0.45, 0.05);
}

TEST(Refine, ThePayloadIsRecordedAtItsFittedPosition) {
  const test::Stages s = test::RunStages({{test::kPayloadMass, 2.5}, {test::kPayloadY, 0.1}}, 4);
  const Refinement& r = s.refinement;
  ASSERT_TRUE(std::isfinite(r.payload_mass));
  EXPECT_NEAR(r.payload_y, 0.1, 0.03);
  EXPECT_NEAR(r.payload_x, 0.0, 0.03);
  bool traced = false;
  for (const auto& t : r.trace) traced |= t.knob.find("payload.mass_kg at (x") == 0;
  EXPECT_TRUE(traced);
}

// The sideways offset is not searched: every point of the search keeps the sideways moment the
// probes read (mass x y), so a heavier point sits nearer the middle, not at the same y.
TEST(Refine, ThePayloadsSearchKeepsItsSidewaysMoment) {
  const test::Stages s = test::RunStages({{test::kPayloadMass, 2.5}, {test::kPayloadY, 0.1}}, 4);
  std::vector<double> moments, masses;
  for (const auto& t : s.refinement.trace) {
    double x = 0, y = 0;
    if (std::sscanf(t.knob.c_str(), "payload.mass_kg at (x %lf, y %lf) m", &x, &y) != 2) continue;
    moments.push_back(t.value * y);
    masses.push_back(t.value);
  }
  ASSERT_GE(moments.size(), 9u);
  EXPECT_GT(*std::max_element(masses.begin(), masses.end()), 2 * *std::min_element(masses.begin(), masses.end()))
      << "the grid spans masses";
  // Within the label's three significant digits.
  EXPECT_LT(*std::max_element(moments.begin(), moments.end()), 1.02 * *std::min_element(moments.begin(), moments.end()));
  EXPECT_NEAR(s.refinement.payload_mass * s.refinement.payload_y, 0.25, 0.25 * 0.25);
}

TEST(Refine, ThePayloadsMassAndForwardOffsetComeFromALikelihoodSearch) {
  const test::Stages s = test::RunStages({{test::kPayloadMass, 2.5}, {test::kPayloadX, 0.12}}, 4);
  const Refinement& r = s.refinement;
  ASSERT_TRUE(std::isfinite(r.payload_mass));
  int scored = 0;
  for (const auto& t : r.trace) scored += std::isfinite(t.score);
  EXPECT_GE(scored, 9) << "a 3 x 3 grid of masses and offsets, each scored";
  EXPECT_NEAR(r.payload_x, 0.12, 0.03);
  const int k = test::CandidateOf(s.set, "payload");
  const auto pos = std::find(r.selection.selected.begin(), r.selection.selected.end(), k);
  ASSERT_NE(pos, r.selection.selected.end());
  const double mass = CandidateValue(s.set, r, k, r.selection.fit.theta[pos - r.selection.selected.begin()]);
  EXPECT_NEAR(mass, 2.5, 0.25 * 2.5);
  ASSERT_FALSE(r.refined.empty());
  EXPECT_TRUE(r.refined.back().converged) << r.refined.back().why;
  // The masses and offsets that fit as well hold the best point; the fake's payload is exact, so
  // a point a mass step (x 1.6) away from the best does not fit as well.
  const SearchSpan& a = r.refined.back().as_well;
  ASSERT_TRUE(a.Searched());
  EXPECT_LE(a.lower, r.payload_mass);
  EXPECT_GE(a.upper, r.payload_mass);
  EXPECT_LE(a.x_lower, r.payload_x);
  EXPECT_GE(a.x_upper, r.payload_x);
  EXPECT_LT(a.upper / a.lower, 1.6 * 1.6) << "not every mass searched";
  EXPECT_LT(a.points, a.searched);
}

TEST(Refine, APayloadCloseBehindTheFirstChoiceIsSearchedToo) {
  SelectionResult sel;
  sel.steps.push_back({3, {{3, 1.0, 0.1, 9.0}, {7, 0.6, 0.1, 5.0}, {8, 0.3, 0.1, 4.0}}, {}, 2.8});
  sel.selected = {3};
  EXPECT_TRUE(PayloadIsAContender(sel, 7, 0.5));
  EXPECT_FALSE(PayloadIsAContender(sel, 7, 0.7)) << "below the share of the best gain";
  EXPECT_TRUE(PayloadIsAContender(sel, 8, 0.2)) << "a lower share admits weaker contenders";
  sel.steps[0].candidates[1].z = 2.0;
  EXPECT_FALSE(PayloadIsAContender(sel, 7, 0.5)) << "not significant";
  sel.selected = {3, 7};
  EXPECT_TRUE(PayloadIsAContender(sel, 7, 0.5)) << "selected";
  EXPECT_FALSE(PayloadIsAContender(SelectionResult{}, 7, 0.5));
}

TEST(Refine, NothingSelectedOnANullPairAndNothingRecorded) {
  const test::Stages s = test::RunStages({}, 4);
  EXPECT_TRUE(s.refinement.selection.selected.empty());
  EXPECT_EQ(s.refinement.recorded, 0);
  EXPECT_FALSE(s.refinement.spread.tested);
}

TEST(Refine, AWiderTrackerNoiseIsTestedAgainstTheKnobsOwnSpread) {
  const test::Stages s = test::RunStages({{test::kTrackerNoise, 2.0}}, 4);
  ASSERT_TRUE(s.refinement.spread.tested);
  EXPECT_TRUE(s.refinement.spread.tracker_needed);
  EXPECT_NEAR(s.refinement.tracker_scale, 2.0, 0.5);
}

}  // namespace
}  // namespace dgmm::sim2real
