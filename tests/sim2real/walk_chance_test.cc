// The walk's own chance (walk_chance.h): the nominal recorded again a negligible payload heavier
// says how far paired executions walk apart, and how much of each probe's signature chance makes.
#include "sim2real/walk_chance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

// The largest and median chance share of the simulated candidates.
void Shares(const CandidateSet& set, double* largest, double* median) {
  std::vector<double> v;
  for (double s : set.chance_share) {
    if (!std::isnan(s)) v.push_back(s);
  }
  ASSERT_FALSE(v.empty());
  std::sort(v.begin(), v.end());
  *largest = v.back(), *median = v[v.size() / 2];
}

// The fake's walk pairs: 3 g moves nothing a signature would notice.
TEST(WalkChance, AWalkThatPairsKeepsItsExecutionsTogetherAndSignaturesOfPhysics) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.7}}, 3);
  const WalkChance& w = s.set.chance;
  ASSERT_TRUE(w.measured) << w.why_not;
  EXPECT_NEAR(w.added_kg, 3e-4 * test::SharedFake().total_mass_kg(), 1e-12);
  EXPECT_LT(w.largest_ratio, 0.01);
  double largest = 0, median = 0;
  Shares(s.set, &largest, &median);
  EXPECT_LT(largest, 0.01);
  EXPECT_EQ(s.set.chance_share.size(), s.set.candidates.size());
  EXPECT_TRUE(std::isnan(s.set.chance_share[test::CandidateOf(s.set, "tracker_bias")])) << "a measurement effect";
}

// Every change decorrelates the chaotic fake's executions: paired ones lie about sqrt 2 sds apart, a
// knob that changes nothing becomes a candidate whose signature is all chance, and a strong effect
// (friction) still shows through it.
TEST(WalkChance, AChaoticWalkSaysSoAndItsSignaturesAreLargelyChance) {
  test::FakeSimulator chaotic;
  chaotic.walk_chaos = 1;
  const test::Stages s = test::RunStages(chaotic, {{test::kFriction, 0.7}}, 3);
  const WalkChance& w = s.set.chance;
  ASSERT_TRUE(w.measured) << w.why_not;
  EXPECT_GT(w.largest_ratio, 1.2);
  EXPECT_LT(w.largest_ratio, 1.7);
  const int inert = test::CandidateOf(s.set, "floor.friction.torsional@0.05");
  ASSERT_GE(inert, 0) << "changes nothing but the walk's way";
  EXPECT_GT(s.set.chance_share[inert], 0.6);
  EXPECT_LT(s.set.chance_share[test::CandidateOf(s.set, "floor.friction@0.6")], 0.5);
}

TEST(WalkChance, NotMeasuredWhenAskedNotAndTooFewPairsSaySo) {
  test::Stages s = test::RunStages({}, 2);
  CandidateOptions options = s.options.candidates;
  options.chance.share = 0;
  const CandidateSet set = BuildCandidates(test::SharedFake(), s.in, s.base, options);
  EXPECT_FALSE(set.chance.measured);
  EXPECT_NE(set.chance.why_not, "");
  for (double share : set.chance_share) EXPECT_TRUE(std::isnan(share));
  const SampleSet few = set.nominal.Subset({0, 1, 2});
  const WalkChance w = MeasureWalkChance(set.nominal, few, s.in.sim_set, s.in.real, 0.003, 5.0);
  EXPECT_FALSE(w.measured);
  EXPECT_NE(w.why_not.find("fell"), std::string::npos) << w.why_not;
  options.chance.share = -1;
  EXPECT_FALSE(options.IsValid(nullptr));
}

}  // namespace
}  // namespace dgmm::sim2real
