// The runoff on uneven ground (runoff.h), on the fake simulator: its contenders are the simulator
// knobs significant at the first selection step, recorded towards their probes; a planted knob is
// named with its value and replaces what the mean shifts named; when it names nothing, a named knob
// keeps its place with the runoff's doubt.
#include "sim2real/runoff.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real::test {
namespace {

RunoffOptions Options(const Stages& s) {
  RunoffOptions o;
  o.search.model = s.options.locate.model;
  return o;
}

TEST(Runoff, ContendersAreTheFirstStepsSignificantKnobsRecordedTowardsTheirProbes) {
  const Stages s = RunStages({{kFriction, 0.6}}, 4);
  std::vector<std::string> contenders;
  const auto grid = RunoffGrid(SharedFake(), s.set, s.refinement, Options(s), &contenders);
  ASSERT_FALSE(contenders.empty());
  bool friction = false;
  for (const auto& [k, v] : grid) {
    const Knob& knob = SharedFake().knobs()[k];
    EXPECT_GE(v, knob.lo);
    EXPECT_LE(v, knob.hi);
    EXPECT_NE(v, knob.nominal);
    friction |= k == kFriction;
  }
  EXPECT_TRUE(friction) << "the planted knob is a contender";
  EXPECT_LE(contenders.size(), 3u);
}

TEST(Runoff, NamesAPlantedKnobAndReplacesAnotherName) {
  const Stages s = RunStages({{kFriction, 0.6}}, 4);
  Runoff r = RunRunoff(SharedFake(), s.in, s.set, s.refinement, s.options.candidates, Options(s));
  ASSERT_TRUE(r.ran) << r.why_not;
  ASSERT_TRUE(r.search.named) << r.search.why;
  EXPECT_EQ(r.search.knob_index, kFriction);
  EXPECT_NEAR(r.search.value, 0.6, 0.25 * 0.6);
  const Correction c = LegSearchCorrection(r.search);
  ASSERT_EQ(c.terms.size(), 1u);
  EXPECT_EQ(c.terms[0].key, SharedFake().knobs()[kFriction].name + "@runoff") << "the model file says which stage named it";
  Verdict v;
  v.status = "partly_explained";
  VerdictNamed latency;
  latency.knob = "actuators.latency_s";
  v.named = {latency};
  v.sentence = "Partly explained: latency.";
  AddRunoff(SharedFake(), &r, &v);
  EXPECT_EQ(v.status, "partly_explained");
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, SharedFake().knobs()[kFriction].name);
  EXPECT_NE(v.sentence.find(v.named[0].knob), std::string::npos) << v.sentence;
  EXPECT_EQ(v.sentence.find("latency."), std::string::npos) << "one story: " << v.sentence;
  bool said = false;
  for (const std::string& d : v.doubts) said |= d.find("had named actuators.latency_s") != std::string::npos;
  EXPECT_TRUE(said) << "the replaced name is said";
}

TEST(Runoff, ARunoffThatNamesNothingLeavesTheNameWithItsDoubt) {
  Runoff r;
  r.ran = true;
  r.contenders = {"a@1", "b@2"};
  r.search.ran = true;
  r.search.why = "the best point is a at 1, but b fits the real samples as well";
  Verdict v;
  v.status = "explained";
  VerdictNamed a;
  a.knob = "a";
  v.named = {a};
  AddRunoff(SharedFake(), &r, &v);
  EXPECT_EQ(v.status, "partly_explained") << "a doubt the runoff raised is not explained";
  ASSERT_EQ(v.named.size(), 1u);
  ASSERT_FALSE(v.named[0].doubts.empty());
  EXPECT_NE(v.named[0].doubts.back().find("b fits the real samples as well"), std::string::npos);
  EXPECT_NE(v.sentence.find("names no knob"), std::string::npos) << v.sentence;
}

// On ground whose placements share an offset (the fake's ground_sd), the misfit measured against
// a second recording at other places is near 0 for the planted point and stands above it for the
// nominal, and costs two recordings.
TEST(Runoff, OnUnevenGroundTheMisfitIsMeasuredAtOtherPlaces) {
  FakeSimulator rough;
  rough.ground_sd = 1.0;
  const Stages s = RunStages(rough, {{kFriction, 0.6}}, 4);
  RunoffOptions o = Options(s);
  o.search.refine_steps = 0;
  o.search.misfit_elsewhere = true;
  const int before = rough.records();
  const Runoff r = RunRunoff(rough, s.in, s.set, s.refinement, s.options.candidates, o);
  ASSERT_TRUE(r.ran) << r.why_not;
  ASSERT_EQ(r.search.knob_index, kFriction) << r.search.why;
  EXPECT_NEAR(r.search.value, 0.6, 0.25 * 0.6);
  EXPECT_GT(r.search.nominal_misfit, 0.1) << "the nominal's misfit is the planted mismatch";
  EXPECT_LT(std::fabs(r.search.best_misfit), 0.5 * r.search.nominal_misfit) << "the planted point's is near 0";
  EXPECT_LE(r.search.best_misfit, o.search.z * r.search.best_misfit_se);
  EXPECT_TRUE(r.search.named) << r.search.why;
  EXPECT_EQ(rough.records() - before, static_cast<int>(r.search.points.size()) + 4)
      << "the nominal twice and the points, then the nominal and the best point at other places";
}

// A point on the way to the planted physics, not at it (friction 0.4 planted, 0.8 and 0.9
// searched): it fits better than the nominal, but the real samples fit its model worse than its own
// recording at other places does, and it is not named.
TEST(Runoff, OnUnevenGroundAPointShortOfThePlantedPhysicsIsNotNamed) {
  FakeSimulator rough;
  rough.ground_sd = 1.0;
  const Stages s = RunStages(rough, {{kFriction, 0.4}}, 4);
  LegSearchOptions o = Options(s).search;
  o.refine_steps = 0;
  o.misfit_elsewhere = true;
  const LegSearch r = SearchOwnModels(rough, s.in, s.set, s.options.candidates, o, {{kFriction, 0.8}, {kFriction, 0.9}});
  ASSERT_TRUE(r.ran) << r.why;
  EXPECT_GT(r.z_vs_nominal, o.z) << "the point fits better than the nominal";
  EXPECT_GT(r.best_misfit, o.z * r.best_misfit_se);
  EXPECT_FALSE(r.named) << r.knob << " at " << r.value;
  EXPECT_NE(r.why.find("at other places"), std::string::npos) << r.why;
}

TEST(Runoff, RejectsOptionsThatCannotRun) {
  RunoffOptions o;
  std::string error;
  o.steps = {};
  EXPECT_FALSE(o.IsValid(&error));
  o.steps = {0.5, -1};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("runoff"), std::string::npos);
  o.steps = {1};
  o.max_contenders = 0;
  EXPECT_FALSE(o.IsValid(&error));
}

}  // namespace
}  // namespace dgmm::sim2real::test
