// The search of every leg's gain (leg_search.h), on the fake simulator's four legs, with its default
// score (the sag mode): a planted weak leg is named with its gain, a nominal "real" robot or physics
// of another kind names none, the verdict says one thing either way, and the answer does not
// depend on the thread count.
#include "sim2real/leg_search.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim2real/recorded_null.h"
#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real::test {
namespace {

LegSearchOptions Options(const Stages& s) {
  LegSearchOptions o;
  o.model = s.options.locate.model;
  return o;
}

LegSearch Search(const Stages& s, int threads = 1) {
  CandidateOptions recording = s.options.candidates;
  recording.recording.threads = threads;
  return SearchLegGains(SharedFake(), s.in, s.set, recording, Options(s));
}

// A verdict that named one knob, with `status`.
Verdict OneNamed(const std::string& status, const std::string& knob) {
  Verdict v;
  v.status = status;
  v.named.resize(1);
  v.named[0].knob = knob;
  return v;
}

TEST(LegSearch, FindsOnlyThePerLegGainKnobs) {
  const std::vector<int> legs = LegGainKnobs(SharedFake());
  EXPECT_EQ(legs, (std::vector<int>{kLeg0Gain, kLeg1Gain, kLeg2Gain, kLeg3Gain}));
}

TEST(LegSearch, FindsTheSidesGainKnobsWhenAsked) {
  EXPECT_EQ(LegGainKnobs(SharedFake(), true),
            (std::vector<int>{kLeg0Gain, kLeg1Gain, kLeg2Gain, kLeg3Gain, kLeftGain, kRightGain}));
}

// With the sides searched beside the legs (a named whole-robot gain challenged), a weak side is
// named as a side, by its side, and the verdict says a side was searched and found.
TEST(LegSearch, WithTheSidesAWeakSideIsNamedAsASide) {
  const Stages s = RunStages({{kLeftGain, 0.45}}, 3);
  const LegSearch r = SearchLegGains(SharedFake(), s.in, s.set, s.options.candidates, Options(s), true);
  ASSERT_TRUE(r.ran);
  EXPECT_TRUE(r.sides_searched);
  ASSERT_TRUE(r.named) << r.why;
  EXPECT_TRUE(r.side);
  EXPECT_EQ(r.leg, "left side");
  EXPECT_EQ(r.knob_index, kLeftGain);
  EXPECT_NEAR(r.value, 0.45, 0.25 * 0.45);
  EXPECT_EQ(LegSaid(r).rfind("left side (gain ", 0), 0u) << LegSaid(r);
  Verdict v = UnexplainedInRegions();
  AddLegSearch(r, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "actuators.side.left.gain");
  EXPECT_NE(v.sentence.find("search of every leg's and every side's gain"), std::string::npos) << v.sentence;
  EXPECT_NE(v.sentence.find("The weak left side fits"), std::string::npos) << v.sentence;
  EXPECT_EQ(v.sentence.find("left side leg"), std::string::npos) << v.sentence;
  EXPECT_FALSE(Search(s).sides_searched) << "the legs alone by default";
}

TEST(LegSearch, NamesAPlantedWeakLegWithItsGain) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  const LegSearch r = Search(s);
  ASSERT_TRUE(r.ran);
  ASSERT_TRUE(r.named) << r.why;
  EXPECT_EQ(r.leg, "leg1");
  EXPECT_EQ(r.knob_index, kLeg1Gain);
  EXPECT_NEAR(r.value, 0.38, 0.25 * 0.38);
  EXPECT_GT(r.z_vs_nominal, 2.0);
  EXPECT_TRUE(r.legs_as_well.empty());
  EXPECT_GE(r.gap_closed, 0.5) << "the weak leg removes most of the nominal's misfit";
  EXPECT_GT(r.nominal_misfit, r.best_misfit);
  EXPECT_LE(r.as_well.lower, r.value);
  EXPECT_GE(r.as_well.upper, r.value);
  EXPECT_GT(r.points.size(), 12u) << "four legs at three gains, then half-steps around the best";
  // The near miss's gain (SearchNearMisses) is the best score minus the nominal's, its z from these rows.
  EXPECT_NEAR(r.best_rows.mean(), BestScore(r), 1e-9 * std::abs(BestScore(r)));
  const Correction c = LegSearchCorrection(r);
  ASSERT_TRUE(static_cast<bool>(c.shift));
  EXPECT_GT(c.Shift(0, s.in.real.z.row(0).transpose(), 0, s.in.real.pose_dim()).norm(), 0);
}

TEST(LegSearch, ANominalRobotNamesNoLeg) {
  const Stages s = RunStages({}, 3);
  const LegSearch r = Search(s);
  ASSERT_TRUE(r.ran);
  EXPECT_FALSE(r.named) << "named " << r.leg << " at " << r.value;
  EXPECT_FALSE(r.why.empty());
  EXPECT_FALSE(static_cast<bool>(LegSearchCorrection(r).shift));
}

TEST(LegSearch, PhysicsOfAnotherKindNamesNoLeg) {
  FakeExtras extras;
  extras.geometry = 0.04;  // no knob describes it
  const Stages s = RunStages({}, 3, extras);
  const LegSearch r = Search(s);
  EXPECT_FALSE(r.named) << "named " << r.leg << " at " << r.value;
}

// A nominal recording that drew badly (a chaotic walk's luck, which a negligibly different recording
// does not repeat) makes every leg beat it; the nominal's second draw, a negligible payload heavier,
// becomes the nominal and no leg is named. Recorded once, the unlucky draw lets a leg through.
TEST(LegSearch, AnUnluckyNominalDrawIsReplacedByItsSecondDraw) {
  FakeSimulator lucky;
  lucky.nominal_luck = 1.5 * 0.01;  // 1.5 sd of dx
  const Stages s = RunStages(lucky, {}, 3);
  LegSearchOptions once = Options(s);
  once.chance.share = 0;
  const LegSearch single = SearchLegGains(lucky, s.in, s.set, s.options.candidates, once);
  ASSERT_TRUE(single.ran);
  EXPECT_FALSE(single.draws.recorded);
  EXPECT_GT(single.z_vs_nominal, 2.0) << "every leg beats the unlucky draw";
  const LegSearch twice = SearchLegGains(lucky, s.in, s.set, s.options.candidates, Options(s));
  ASSERT_TRUE(twice.draws.recorded);
  EXPECT_TRUE(twice.draws.second_is_nominal);
  EXPECT_GT(twice.draws.z_second, 2.0);
  EXPECT_NEAR(twice.draws.added_kg, 3e-4 * lucky.total_mass_kg(), 1e-12);
  EXPECT_DOUBLE_EQ(twice.nominal_score, twice.draws.second);
  EXPECT_LT(twice.z_vs_nominal, 2.0);
  EXPECT_FALSE(twice.named) << "named " << twice.leg << " at " << twice.value;
  EXPECT_GT(twice.draws.chance, 0);
  EXPECT_NE(twice.why.find("the walk's own chance"), std::string::npos) << twice.why;
}

// Where the walk pairs, the two draws score alike and the first stays the nominal.
TEST(LegSearch, APairingWalksTwoNominalDrawsScoreAlike) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  const LegSearch r = Search(s);
  ASSERT_TRUE(r.draws.recorded);
  EXPECT_LT(std::fabs(r.draws.z_second), 2.0);
  EXPECT_LT(std::fabs(r.draws.second - r.draws.first), 0.05 * std::fabs(r.best_plain - r.draws.first));
  EXPECT_LT(r.draws.chance, 0.05 * std::fabs(r.best_plain - r.draws.first));
}

// With several draws per point every point and both nominal draws are recorded that many times,
// and a planted weak leg is still named.
TEST(LegSearch, SeveralDrawsPerPointRecordEachThatManyTimes) {
  FakeSimulator fake;
  const Stages s = RunStages(fake, {{kLeg1Gain, 0.38}}, 3);
  LegSearchOptions o = Options(s);
  o.draws = 3;
  o.refine_steps = 0;
  CandidateOptions recording = s.options.candidates;
  recording.recording.cache_dir = "-";
  const int before = fake.records();
  const LegSearch r = SearchLegGains(fake, s.in, s.set, recording, o);
  ASSERT_TRUE(r.named) << r.why;
  EXPECT_EQ(r.leg, "leg1");
  EXPECT_NEAR(r.draws.added_kg, 3 * 3e-4 * fake.total_mass_kg(), 1e-12) << "the second nominal starts after the first's draws";
  EXPECT_EQ(fake.records() - before, 3 * static_cast<int>(r.points.size()) + 2 * 3);
  o.draws = 0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
}

// A point the same-place gate refuses gets a second look at other places (second_look_elsewhere):
// a planted weak leg is named after it, checked against a recording of the point elsewhere;
// physics of another kind still names no leg.
TEST(LegSearch, ASecondLookAtOtherPlacesNamesALegTheSamePlaceGateRefused) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  LegSearchOptions o = Options(s);
  o.min_gap_closed = 1;  // a share of the nominal's misfit no point removes here
  o.second_look_elsewhere = false;
  const LegSearch refused = SearchLegGains(SharedFake(), s.in, s.set, s.options.candidates, o);
  ASSERT_FALSE(refused.named) << "gap closed " << refused.gap_closed;
  EXPECT_FALSE(refused.misfit_elsewhere);
  EXPECT_NE(refused.why.find("of the nominal's misfit"), std::string::npos) << refused.why;
  o.second_look_elsewhere = true;
  const LegSearch second = SearchLegGains(SharedFake(), s.in, s.set, s.options.candidates, o);
  ASSERT_TRUE(second.named) << second.why;
  EXPECT_EQ(second.leg, "leg1");
  EXPECT_NEAR(second.value, 0.38, 0.25 * 0.38);
  EXPECT_TRUE(second.misfit_elsewhere);
  EXPECT_LE(second.best_misfit, o.z * second.best_misfit_se);
  FakeExtras extras;
  extras.geometry = 0.04;  // no knob describes it
  const Stages g = RunStages({}, 3, extras);
  const LegSearch other = SearchLegGains(SharedFake(), g.in, g.set, g.options.candidates, o);
  EXPECT_FALSE(other.named) << "named " << other.leg << " at " << other.value;
}

// The shared fake, but the robot falls in every placement of a recording at `seed`.
class FallsAt : public KnobSimulator {
 public:
  explicit FallsAt(std::uint64_t seed) : seed_(seed) {}
  const std::vector<Knob>& knobs() const override { return SharedFake().knobs(); }
  std::string Fingerprint() const override { return SharedFake().Fingerprint() + "-falls"; }
  SampleSet Record(const Recording& r, const std::vector<KnobValue>& v, int threads) const override {
    const SampleSet s = SharedFake().Record(r, v, threads);
    return r.seed == seed_ ? s.Subset({}) : s;
  }
  CellRecording RecordCell(const Cell& c, const std::vector<KnobValue>& v) const override {
    return SharedFake().RecordCell(c, v);
  }
  std::string ConfigJson(const std::vector<KnobValue>& v) const override { return SharedFake().ConfigJson(v); }
  double total_mass_kg() const override { return SharedFake().total_mass_kg(); }
  double leg_reach_m() const override { return SharedFake().leg_reach_m(); }

 private:
  std::uint64_t seed_;
};

// Where the robot fell in the recording at other places there is no model to compare the real
// samples with: nothing is named through the gate, and the reason says so (not a misfit of NaN).
TEST(LegSearch, AGateAtOtherPlacesWhereTheRobotFellNamesNothing) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  LegSearchOptions o = Options(s);
  o.min_gap_closed = 1;  // refused at the same places, so the second look at other places decides
  o.elsewhere_seed = 777;
  const FallsAt falls(RealDesign(s.in, o.elsewhere_seed).seed);
  const LegSearch r = SearchLegGains(falls, s.in, s.set, s.options.candidates, o);
  EXPECT_TRUE(r.misfit_elsewhere);
  EXPECT_FALSE(r.named) << "named " << r.leg << " at " << r.value;
  EXPECT_TRUE(std::isnan(r.best_misfit));
  EXPECT_NE(r.why.find("no model to compare at other places"), std::string::npos) << r.why;
}

TEST(LegSearch, TheAnswerDoesNotDependOnTheThreadCount) {
  const Stages s = RunStages({{kLeg2Gain, 0.4}}, 3);
  const LegSearch one = Search(s, 1), two = Search(s, 2);
  ASSERT_EQ(one.points.size(), two.points.size());
  for (size_t j = 0; j < one.points.size(); ++j) EXPECT_EQ(one.points[j].score, two.points[j].score);
  EXPECT_EQ(one.value, two.value);
}

TEST(LegSearch, ANamedLegIsTheVerdictsOneStory) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  const LegSearch r = Search(s);
  ASSERT_TRUE(r.named);
  Verdict v = UnexplainedInRegions();
  AddLegSearch(r, &v);
  EXPECT_EQ(v.status, "partly_explained");
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "actuators.leg1.gain");
  EXPECT_EQ(v.named[0].value, r.value);
  EXPECT_EQ(v.sentence.find("Unexplained"), std::string::npos) << v.sentence;
  EXPECT_NE(v.sentence.find("actuators.leg1.gain"), std::string::npos) << v.sentence;
  EXPECT_NE(v.sentence.find("search of every leg's gain"), std::string::npos) << v.sentence;
  for (const std::string& d : v.doubts) EXPECT_EQ(d.find("regions"), std::string::npos) << "the old doubt stays: " << d;
}

TEST(LegSearch, ALegNamedByNoneIsSaidWithWhy) {
  const Stages s = RunStages({}, 3);
  const LegSearch r = Search(s);
  Verdict v;
  v.status = "unexplained";
  v.sentence = "Unexplained mismatch: no simulator knob or measurement effect fits.";
  AddLegSearch(r, &v);
  EXPECT_EQ(v.status, "unexplained");
  EXPECT_TRUE(v.named.empty());
  EXPECT_NE(v.sentence.find("names no leg: " + r.why), std::string::npos) << v.sentence;
}

// A challenge of knobs named before the search (LegSearchOptions::challenge_named): the weak leg
// keeps its name only when its recording fits the real samples better than their correction did.
TEST(LegSearch, AChallengedNameGivesWayOnlyToALegThatFitsBetter) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  const std::vector<std::string> before = {"tracker.yaw_drift", "bodies.mass_scale"};
  LegSearch poor = Search(s);
  ASSERT_TRUE(poor.named) << poor.why;
  // A correction no better than the nominal recording's model: the leg wins, and the verdict says
  // what it replaced.
  LegSearchChallenge(s.in, before, poor.nominal_model.LogLikelihood(s.in.real), Options(s), &poor);
  EXPECT_TRUE(poor.named) << poor.why;
  EXPECT_GT(poor.z_vs_named, 2.0);
  EXPECT_EQ(poor.challenged, before);
  Verdict v;
  v.status = "partly_explained";
  v.sentence = "Simulator knobs and measurement effects, in order of evidence: (1) heading_drift.";
  AddLegSearch(poor, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "actuators.leg1.gain");
  EXPECT_EQ(v.sentence.find("heading_drift ("), std::string::npos) << "one story: " << v.sentence;
  EXPECT_NE(v.named[0].doubts[0].find("named tracker.yaw_drift and bodies.mass_scale"), std::string::npos)
      << v.named[0].doubts[0];
  // A correction that fits every real sample better than the leg's recording: the leg gives way.
  LegSearch good = Search(s);
  const Eigen::VectorXd better = good.best_rows.array() + 1.0;
  LegSearchChallenge(s.in, before, better, Options(s), &good);
  EXPECT_FALSE(good.named);
  EXPECT_LT(good.z_vs_named, 0);
  EXPECT_NE(good.why.find("no better than the named knobs' correction"), std::string::npos) << good.why;
  EXPECT_FALSE(good.rivals_named);
  Verdict kept = OneNamed("partly_explained", "tracker.yaw_drift");
  AddLegSearch(good, &kept);
  EXPECT_TRUE(kept.doubts.empty()) << "a leg that fits worse is no rival";
  ASSERT_EQ(kept.named.size(), 1u);
  EXPECT_EQ(kept.named[0].knob, "tracker.yaw_drift");
  EXPECT_NE(kept.sentence.find("names no leg: " + good.why), std::string::npos) << kept.sentence;
}

// A challenged name that the leg's recording beats, but by under the search's bar: the name stays,
// and the verdict says the data do not tell the weak leg from it.
TEST(LegSearch, ALegThatFitsBetterButNotByTheBarIsADoubtOfTheNamedKnobs) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  const std::vector<std::string> before = {"payload.mass_kg"};
  const LegSearch found = Search(s);
  ASSERT_TRUE(found.named) << found.why;
  // Corrections that fit some placements better and others worse than the leg's recording, by `t`
  // nats per sample: the wider the spread, the nearer 0 the leg's z over them.
  LegSearch rival;
  for (double t : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {
    Eigen::VectorXd corrected = found.best_rows;
    for (int i = 0; i < corrected.size(); ++i) corrected(i) += (s.in.real.episode[i] % 2 ? t : -t);
    rival = found;
    LegSearchChallenge(s.in, before, corrected, Options(s), &rival);
    if (rival.z_vs_named > 0 && rival.z_vs_named < Options(s).z) break;
  }
  ASSERT_GT(rival.z_vs_named, 0);
  ASSERT_LT(rival.z_vs_named, Options(s).z);
  EXPECT_FALSE(rival.named);
  EXPECT_TRUE(rival.rivals_named);
  EXPECT_NE(rival.why.find("better than the named knobs' correction, but by under 2 SE"), std::string::npos) << rival.why;
  Verdict v = OneNamed("explained", "payload.mass_kg");
  AddLegSearch(rival, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "payload.mass_kg");
  EXPECT_EQ(v.status, "partly_explained") << "a rival reading is a doubt";
  ASSERT_FALSE(v.doubts.empty());
  EXPECT_NE(v.doubts.back().find("a weak leg1 leg"), std::string::npos) << v.doubts.back();
  EXPECT_NE(v.doubts.back().find("do not tell the two apart"), std::string::npos) << v.doubts.back();
  EXPECT_NE(v.doubts.back().find("under the search's bar of 2)"), std::string::npos) << v.doubts.back();
}

// The other score (a broad component instead of the default sag mode) on the same fake: a planted
// weak leg is named with its gain, a nominal robot names none, and the answer does not depend on
// the thread count.
TEST(LegSearch, TheRobustScoreNamesAPlantedWeakLegAndNoLegOfANominalRobot) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  LegSearchOptions o = Options(s);
  o.sag_mode = false;
  CandidateOptions recording = s.options.candidates;
  const LegSearch r = SearchLegGains(SharedFake(), s.in, s.set, recording, o);
  ASSERT_TRUE(r.named) << r.why;
  EXPECT_EQ(r.score, "robust");
  EXPECT_EQ(r.leg, "leg1");
  EXPECT_NEAR(r.value, 0.38, 0.25 * 0.38);
  recording.recording.threads = 2;
  const LegSearch two = SearchLegGains(SharedFake(), s.in, s.set, recording, o);
  EXPECT_EQ(two.value, r.value);
  EXPECT_EQ(two.points.back().score, r.points.back().score);
  const Stages null = RunStages({}, 3);
  const LegSearch n = SearchLegGains(SharedFake(), null.in, null.set, null.options.candidates, o);
  EXPECT_FALSE(n.named) << "named " << n.leg << " at " << n.value;
}

TEST(LegSearch, RejectsOptionsThatCannotSearch) {
  LegSearchOptions o;
  std::string error;
  o.factors = {};
  EXPECT_FALSE(o.IsValid(&error));
  o.factors = {0.5, -0.1};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("leg search"), std::string::npos);
  o.factors = {0.5};
  o.min_gap_closed = 2;
  EXPECT_FALSE(o.IsValid(&error));
  o.min_gap_closed = 0.25;
  EXPECT_TRUE(o.IsValid(&error)) << error;
  o.sag.broad_scale = 0.5;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("sag"), std::string::npos);
}

}  // namespace
}  // namespace dgmm::sim2real::test
