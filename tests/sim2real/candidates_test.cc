// Stage 3: every knob probe a candidate, the payload one three-parameter candidate, the tracker's
// spread probe kept apart, an inert knob left out, per-leg probes only when a side is implicated.
#include "sim2real/candidates.h"

#include <gtest/gtest.h>

#include "tests/sim2real/stage_fixture.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

TEST(Candidates, TheLibraryOfAFakeWithoutAnImplicatedSide) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.7}}, 3);
  const CandidateSet& set = s.set;
  EXPECT_FALSE(set.legs_probed) << set.legs_note;
  EXPECT_EQ(set.inert_knobs, std::vector<std::string>{"floor.friction.torsional"});
  for (const std::string key : {"tracker_bias", "tracker_noise", "floor.friction@0.6", "payload", "imu_bias",
                                "heading_drift", "actuators.side.left.gain@0.5"}) {
    EXPECT_GE(test::CandidateOf(set, key), 0) << key;
  }
  EXPECT_LT(test::CandidateOf(set, "actuators.leg0.gain@0.5"), 0);
  EXPECT_GE(set.tracker_shift, 0);
  EXPECT_EQ(set.library[test::CandidateOf(set, "payload")].num_params(), 3);
  // nominal, its replica a negligible payload heavier (walk_chance.h) + the probes of every knob but the legs
  EXPECT_EQ(set.requests, 2 + test::kNumFakeKnobs - 4);
  EXPECT_EQ(set.candidates.size(), set.library.size());
  EXPECT_EQ(set.candidates.size(), set.externals.size());
}

TEST(Candidates, AWeakLegImplicatesItsSideAndThenThatSidesLegsAreProbed) {
  const test::Stages s = test::RunStages({{test::kLeg2Gain, 0.3}}, 3);
  EXPECT_TRUE(s.set.legs_probed) << s.set.legs_note;
  EXPECT_NE(s.set.legs_note.find("right"), std::string::npos) << s.set.legs_note;
  EXPECT_NE(s.set.legs_note.find("that side only"), std::string::npos) << s.set.legs_note;
  for (int leg = 0; leg < 4; ++leg) {  // the fake's legs 2 and 3 are on the right
    EXPECT_EQ(test::CandidateOf(s.set, "actuators.leg" + std::to_string(leg) + ".gain@0.5") >= 0, leg >= 2) << leg;
  }
}

TEST(Candidates, EveryLegIsProbedWhenAsked) {
  // dgmm sim2real --every-leg: no first pass decides, every leg's gain is a candidate.
  test::Stages s = test::RunStages({}, 2);
  CandidateOptions options = s.options.candidates;
  options.legs_only_when_implicated = false;
  const CandidateSet set = BuildCandidates(test::SharedFake(), s.in, s.base, options);
  EXPECT_TRUE(set.legs_probed);
  EXPECT_NE(set.legs_note.find("(always)"), std::string::npos) << set.legs_note;
  for (int leg = 0; leg < 4; ++leg) EXPECT_GE(test::CandidateOf(set, "actuators.leg" + std::to_string(leg) + ".gain@0.5"), 0);
}

// CandidateOptions::only_knobs (the run again with every execution): those knobs' probes alone,
// a leg among them recorded without a side's first pass, the measurement effects as always; an
// index past the simulator's knobs is refused.
TEST(Candidates, OnlyTheScreenedKnobsAreRecorded) {
  test::Stages s = test::RunStages({}, 2);
  CandidateOptions options = s.options.candidates;
  options.only_knobs = std::vector<int>{test::kPayloadY, test::kFriction, test::kPayloadMass, test::kPayloadX,
                                        test::kLeg1Gain, test::kFriction};
  const CandidateSet set = BuildCandidates(test::SharedFake(), s.in, s.base, options);
  EXPECT_EQ(set.requests, 2 + 5) << "the nominal, its replica and five knobs' probes, each once";
  for (const std::string key : {"tracker_bias", "tracker_noise", "floor.friction@0.6", "payload",
                                "actuators.leg1.gain@0.5"}) {
    EXPECT_GE(test::CandidateOf(set, key), 0) << key;
  }
  EXPECT_LT(test::CandidateOf(set, "actuators.side.left.gain@0.5"), 0);
  EXPECT_TRUE(set.legs_probed) << set.legs_note;
  options.only_knobs = std::vector<int>{test::kNumFakeKnobs};
  EXPECT_THROW(BuildCandidates(test::SharedFake(), s.in, s.base, options), InputError);
  options.only_knobs = std::vector<int>{-1};
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
}

// The run again keeps the first look's other candidates with their signatures: every key once,
// the kept ones' shifts those of the first look.
TEST(Candidates, TheFirstLooksOtherCandidatesAreKept) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.7}}, 3);
  CandidateOptions options = s.options.candidates;
  options.only_knobs = std::vector<int>{test::kFriction};
  CandidateSet again = BuildCandidates(test::SharedFake(), s.in, s.base, options);
  const int own = static_cast<int>(again.candidates.size());
  const int kept = KeepFirstLookCandidates(s.set, *options.only_knobs, &again);
  EXPECT_EQ(own + kept, static_cast<int>(s.set.candidates.size()));
  for (const KnobCandidate& c : s.set.candidates) EXPECT_GE(test::CandidateOf(again, c.key), 0) << c.key;
  const int payload = test::CandidateOf(again, "payload");
  ASSERT_GE(payload, own) << "kept, not recorded";
  EXPECT_EQ(again.payload_knob[0], test::kPayloadMass);
  const PairedShift& kept_shift = again.shifts[again.externals[payload].shifts[0]];
  const PairedShift& first_shift = s.set.shifts[s.set.externals[test::CandidateOf(s.set, "payload")].shifts[0]];
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(s.in.real.terrain_dim());
  EXPECT_EQ(kept_shift.Shift(0, z, 1.0), first_shift.Shift(0, z, 1.0));
  EXPECT_EQ(kept_shift.pairs(), first_shift.pairs());
  EXPECT_EQ(again.candidates.size(), again.library.size());
  EXPECT_EQ(again.candidates.size(), again.externals.size());
  ASSERT_EQ(again.chance_share.size(), again.candidates.size());
  EXPECT_EQ(again.chance_share[payload], s.set.chance_share[test::CandidateOf(s.set, "payload")])
      << "a kept candidate keeps its first look's share of chance";
}

// A screen of no knob (a first look whose finding was a measurement effect, on a robot without a
// tracker noise knob) records the nominal alone, not every knob; the run again keeps every
// simulated candidate of the first look.
TEST(Candidates, AnEmptyScreenRecordsTheNominalAlone) {
  const test::Stages s = test::RunStages({}, 3);
  CandidateOptions options = s.options.candidates;
  options.only_knobs = std::vector<int>{};
  CandidateSet again = BuildCandidates(test::SharedFake(), s.in, s.base, options);
  EXPECT_EQ(again.requests, 2) << "the nominal and its replica";
  for (const KnobCandidate& c : again.candidates) EXPECT_FALSE(c.simulated) << c.key;
  EXPECT_GE(test::CandidateOf(again, "tracker_bias"), 0);
  EXPECT_FALSE(again.legs_probed);
  const int own = static_cast<int>(again.candidates.size());
  const int kept = KeepFirstLookCandidates(s.set, {}, &again);
  EXPECT_GT(kept, 0);
  EXPECT_EQ(own + kept, static_cast<int>(s.set.candidates.size()));
}

TEST(Candidates, MeasurementEffectsRankedAboveASideDoNotHideIt) {
  // The hexapod's weak front leg in one first pass (seed 25002): tracker noise, then three knobs,
  // nothing selected; the right side's gain ranks fourth overall but third among the knobs.
  const test::Stages s = test::RunStages({}, 3);
  const int noise = test::CandidateOf(s.set, "tracker_noise");
  const int friction = test::CandidateOf(s.set, "floor.friction@0.6");
  const int latency = test::CandidateOf(s.set, "actuators.latency_s@0.04");
  const int right = test::CandidateOf(s.set, "actuators.side.right.gain@0.5");
  SelectionResult sel;
  sel.steps.push_back({-1, {{noise, 13.5, 10.2, 1.3}, {friction, 0.13, 0.07, 1.8}, {latency, 0.07, 0.18, 0.4},
                            {right, 0.06, 0.03, 2.0}}, {}, 3.1});
  std::string why;
  const std::vector<int> sides = ImplicatedSides(s.set, sel, s.options.candidates, &why);
  ASSERT_EQ(sides.size(), 1u);
  EXPECT_EQ(sides[0], test::kRightGain);
  EXPECT_NE(why.find("ranked 3 among the simulator's knobs"), std::string::npos) << why;
  sel.steps[0].candidates[3].z = 0.5;
  EXPECT_TRUE(ImplicatedSides(s.set, sel, s.options.candidates, &why).empty()) << "below side_min_z";
  sel.steps[0].candidates.insert(sel.steps[0].candidates.begin() + 1, {test::CandidateOf(s.set, "payload"), 0.2, 0.05, 4});
  sel.steps[0].candidates[4].z = 2.0;
  EXPECT_TRUE(ImplicatedSides(s.set, sel, s.options.candidates, &why).empty()) << "fourth among the knobs";
}

TEST(Candidates, ACandidatesDesignIsItsRecordedShift) {
  const test::Stages s = test::RunStages({}, 3);
  const FitProblem fp = MakeCandidateProblem(s.in, s.base, s.set);
  const int k = test::CandidateOf(s.set, "floor.friction@0.6");
  ASSERT_GE(k, 0);
  const int i = 3;
  const Eigen::VectorXd d = fp.d[k].middleRows(i * fp.dx, fp.dx);
  const Eigen::VectorXd expected = s.set.shifts[s.set.externals[k].shifts[0]].Shift(
      s.in.real.command[i], s.in.real.z.row(i).transpose(), s.in.real.first_execution[i]);
  EXPECT_TRUE(d.isApprox(expected));
}

// The candidates of `simulator` on a pair with friction planted at 0.7.
CandidateSet CandidatesOfPlantedFriction(const test::FakeSimulator& simulator) {
  const test::FakePair pair = test::MakeFakePair(simulator, {{test::kFriction, 0.7}});
  const AnalysisOptions options = test::FastOptions();
  const AnalysisInputs in = PrepareInputs(pair.sim, pair.real, options.seed);
  const Baseline base = LocateMismatch(in, options.locate);
  return BuildCandidates(simulator, in, base, options.candidates);
}

// A probe at which the robot falls in most placements leaves too few paired samples for a
// signature: it is listed, not a candidate, and the other candidates stand.
TEST(Candidates, AProbeThatTopplesTheRobotIsListedNotFatal) {
  test::FakeSimulator toppling;
  toppling.topples_below_friction = 0.65;  // the friction probe (0.6) falls
  const CandidateSet set = CandidatesOfPlantedFriction(toppling);
  EXPECT_EQ(set.unwalkable_probes, std::vector<std::string>{"floor.friction@0.6"});
  EXPECT_LT(test::CandidateOf(set, "floor.friction@0.6"), 0);
  EXPECT_GE(test::CandidateOf(set, "payload"), 0);
  EXPECT_GE(test::CandidateOf(set, "actuators.side.left.gain@0.5"), 0);
}

// When a side probe topples the robot the sides cannot say whether a leg is weak: every leg is
// probed instead.
TEST(Candidates, ASideProbeThatTopplesTheRobotSendsStraightToTheLegs) {
  test::FakeSimulator toppling;
  toppling.topples_below_side_gain = 0.55;  // the side probes (0.5) fall
  const CandidateSet set = CandidatesOfPlantedFriction(toppling);
  EXPECT_EQ(set.unwalkable_probes.size(), 2u);
  EXPECT_TRUE(set.legs_probed) << set.legs_note;
  EXPECT_NE(set.legs_note.find("toppled"), std::string::npos) << set.legs_note;
  EXPECT_GE(test::CandidateOf(set, "actuators.leg1.gain@0.5"), 0);
}

}  // namespace
}  // namespace dgmm::sim2real
