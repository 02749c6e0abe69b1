// Stage 6: the correction is checked before any verdict. A friction beyond the knob's range is
// pinned at the limit and doubted; physics no knob has leaves located mismatch; an in-library
// knob leaves no doubt; the gap closed and its SE follow the delta method.
#include "sim2real/adequacy.h"

#include <gtest/gtest.h>

#include "sim2real/sentence_format.h"
#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

const KnobCheck* CheckOf(const test::Stages& s, const std::string& family) {
  for (const auto& c : s.adequacy.checks) {
    if (s.set.candidates[c.candidate].family == family) return &c;
  }
  return nullptr;
}

TEST(Adequacy, APlantedKnobInsideItsRangeLeavesNoDoubt) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.6}}, 6);
  const KnobCheck* c = CheckOf(s, "friction");
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->doubts.empty());
  EXPECT_TRUE(s.adequacy.doubts.empty()) << s.adequacy.doubts.front();
  EXPECT_TRUE(s.adequacy.remaining.empty());
  EXPECT_FALSE(s.adequacy.below_ceiling);
}

// A named knob whose fitted effect is largely the walk's own chance (walk_chance.h) is doubted with
// the flag; on a walk that pairs it is not. The chance here is the chaotic fake's, and the share
// it makes of the fake friction's effect decides against the threshold.
TEST(Adequacy, ANamedKnobWhoseEffectIsLargelyChanceIsDoubted) {
  test::Stages s = test::RunStages({{test::kFriction, 0.6}}, 6);
  const KnobCheck* clear = CheckOf(s, "friction");
  ASSERT_NE(clear, nullptr);
  const size_t at = clear - s.adequacy.checks.data();
  EXPECT_FALSE(clear->chaotic);
  EXPECT_LT(clear->chance_share, 0.05);
  test::FakeSimulator chaotic;
  chaotic.walk_chaos = 1;
  const std::vector<KnobValue> gram = {{test::kPayloadMass, 0.003}};
  s.set.chance = MeasureWalkChance(chaotic.Record(s.set.recording, {}, 1), chaotic.Record(s.set.recording, gram, 1),
                                   s.in.sim_set, s.in.real, 0.003, 5.0);
  ASSERT_TRUE(s.set.chance.measured);
  const double share = FittedChanceShare(s.set.chance, s.refinement.problem.d[clear->candidate],
                                         s.refinement.selection.fit.theta[at], s.in.real);
  ASSERT_GT(share, 0.05);
  AdequacyOptions options = s.options.adequacy;
  options.max_chance_share = 1.1 * share;
  EXPECT_FALSE(AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, options).checks[at].chaotic);
  options.max_chance_share = 0.9 * share;
  const KnobCheck c = AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, options).checks[at];
  EXPECT_TRUE(c.chaotic);
  EXPECT_NEAR(c.chance_share, share, 1e-12);
  ASSERT_EQ(c.doubts.size(), 1u);
  EXPECT_NE(c.doubts[0].find(Fmt("makes %.2f of its fitted effect", share)), std::string::npos) << c.doubts[0];
  EXPECT_NE(c.doubts[0].find(Fmt("by %.2f of their spread in ", s.set.chance.largest_ratio)), std::string::npos)
      << c.doubts[0];
}

// On a chaotic walk a measurement effect's signature is exact while the simulator's knobs' are
// chance: a named tracker offset may stand in for physics, and says so.
TEST(Adequacy, AMeasurementEffectNamedOnAChaoticWalkIsDoubted) {
  test::FakeExtras extras;
  extras.tracker_bias = Eigen::Vector3d(0.01, 0, 0);
  test::Stages s = test::RunStages({}, 6, extras);
  const KnobCheck* bias = CheckOf(s, "tracker_bias");
  ASSERT_NE(bias, nullptr);
  EXPECT_FALSE(bias->chaotic);
  for (double& share : s.set.chance_share) share = std::isnan(share) ? share : 0.9;
  const Adequacy a = AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, s.options.adequacy);
  const KnobCheck& c = a.checks[bias - s.adequacy.checks.data()];
  EXPECT_TRUE(c.chaotic);
  ASSERT_FALSE(c.doubts.empty());
  EXPECT_NE(c.doubts.back().find("may stand in for physics"), std::string::npos) << c.doubts.back();
}

// A search whose scores dipped (refine_search.h, DeepestDip): the knob's check carries its words as
// a doubt and the flag, and the verdict is no longer `explained`.
TEST(Adequacy, ASearchThatDoesNotRiseToOnePeakIsDoubted) {
  test::Stages s = test::RunStages({{test::kFriction, 0.6}}, 4);
  ASSERT_FALSE(s.refinement.refined.empty());
  KnobRefinement& f = s.refinement.refined[0];
  ASSERT_EQ(f.rugged, "") << "the fake's friction rises to one peak";
  f.rugged = "its likelihood search does not rise to one peak";
  std::mt19937_64 rng(2);
  s.confidence = AssessConfidence(s.set, s.refinement, rng);
  const Adequacy a = AssessAdequacy(s.in, s.base, {}, s.set, s.refinement, s.options.adequacy);
  const KnobCheck* c = nullptr;
  for (const auto& check : a.checks) c = check.candidate == f.candidate ? &check : c;
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->rugged);
  ASSERT_EQ(c->doubts.size(), 1u);
  EXPECT_EQ(c->doubts[0], f.knob + ": its likelihood search does not rise to one peak");
  const Naming naming = DecideNamed(s.set, s.refinement, s.confidence, a, s.options.verdict);
  const Verdict v = ComposeVerdict(s.base, s.set, s.refinement, s.confidence, a, naming, {}, s.options.verdict);
  ASSERT_FALSE(v.named.empty());
  EXPECT_EQ(v.named[0].flags, std::vector<std::string>{"not_single_peaked"});
  EXPECT_NE(v.status, "explained");
}

TEST(Adequacy, AValueBelowTheRangeIsPinnedAndDoubted) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.02}}, 6);
  const KnobCheck* c = CheckOf(s, "friction");
  ASSERT_NE(c, nullptr);
  EXPECT_TRUE(c->pinned_low || c->outside_range);
  EXPECT_NEAR(c->value, 0.3, 1e-9);  // at the range's lower end
  ASSERT_FALSE(c->doubts.empty());
  EXPECT_NE(c->doubts[0].find("floor.friction"), std::string::npos) << c->doubts[0];
}

TEST(Adequacy, PhysicsNoKnobDescribesLeavesLocatedMismatch) {
  test::FakeExtras extras;
  extras.geometry = 0.03;
  const test::Stages s = test::RunStages({}, 6, extras);
  EXPECT_FALSE(s.adequacy.doubts.empty());
}

TEST(Adequacy, OnlyTheShortfallBeyondTheSimSetsOwnSizeIsADoubt) {
  test::FakeExtras extras;
  extras.geometry = 0.03;
  test::Stages s = test::RunStages({}, 5, extras);
  s.null = {};  // no null: the whole shortfall counts
  const Adequacy whole = AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, s.options.adequacy);
  ASSERT_TRUE(whole.below_ceiling) << whole.shortfall << " SE " << whole.shortfall_se;
  EXPECT_DOUBLE_EQ(whole.excess_shortfall, whole.shortfall);
  // A null that accounts for all but a sliver of it leaves no doubt about the fit ...
  s.null.mean = whole.shortfall - 0.01;
  s.null.draws = 20;
  const Adequacy within = AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, s.options.adequacy);
  EXPECT_FALSE(within.below_ceiling);
  EXPECT_NEAR(within.excess_shortfall, 0.01, 1e-12);
  // ... and a null as large but spread wider than the excess is no doubt either.
  s.null.mean = 0;
  s.null.sd = whole.shortfall;
  EXPECT_FALSE(AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, s.options.adequacy).below_ceiling);
}

TEST(Adequacy, GapClosedAndItsStandardError) {
  // corrected - sim = 1 and ceiling - sim = 2 in every episode: half the gap, no spread.
  const Eigen::VectorXd sim = Eigen::VectorXd::Zero(6), corrected = Eigen::VectorXd::Ones(6);
  const Eigen::VectorXd ceiling = Eigen::VectorXd::Constant(6, 2.0);
  double gap, se;
  GapClosed(sim, corrected, ceiling, {0, 0, 1, 1, 2, 2}, &gap, &se);
  EXPECT_DOUBLE_EQ(gap, 0.5);
  EXPECT_NEAR(se, 0.0, 1e-12);
  GapClosed(sim, corrected, sim, {0, 0, 1, 1, 2, 2}, &gap, &se);
  EXPECT_TRUE(std::isnan(gap));  // no gap to close
  Eigen::VectorXd noisy = corrected;
  noisy(0) = 3, noisy(2) = -1;
  GapClosed(sim, noisy, ceiling, {0, 0, 1, 1, 2, 2}, &gap, &se);
  EXPECT_DOUBLE_EQ(gap, 0.5);
  EXPECT_GT(se, 0.1);
}

}  // namespace
}  // namespace dgmm::sim2real
