// The search of a payload's mass and position (payload_search.h) on the fake simulator: a planted
// payload behind the middle is named with its mass and side, a nominal "real" robot names none, the
// verdict says one thing either way, and in the whole analysis the search runs only when enabled
// and nothing else was named.
#include "sim2real/payload_search.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim2real/analysis.h"
#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real::test {
namespace {

PayloadSearch Search(const Stages& s) {
  PayloadSearchOptions o;
  o.search.model = s.options.locate.model;
  return SearchPayload(SharedFake(), s.in, s.set, s.options.candidates, o);
}

TEST(PayloadSearch, FindsThePayloadsThreeKnobs) {
  const PayloadKnobs k = FindPayloadKnobs(SharedFake());
  EXPECT_EQ(k.mass, kPayloadMass);
  EXPECT_EQ(k.x, kPayloadX);
  EXPECT_EQ(k.y, kPayloadY);
}

TEST(PayloadSearch, NamesAPlantedPayloadWithItsMassAndSide) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  const PayloadSearch p = Search(s);
  ASSERT_TRUE(p.ran);
  ASSERT_TRUE(p.search.named) << p.why;
  EXPECT_EQ(p.search.by, "payload_search") << "what the report says corrected the model";
  EXPECT_EQ(p.search.knob_index, kPayloadMass);
  EXPECT_NEAR(p.search.value, 2.4, 0.25 * 2.4);
  EXPECT_LT(p.x, 0) << "behind the middle";
  EXPECT_NEAR(p.search.value * p.x, 2.4 * -0.1, 0.25 * 0.24) << "its moment";
  EXPECT_EQ(p.y, 0);
  EXPECT_EQ(p.columns.size(), 9u) << "five forward offsets and two sideways, then half-steps either side of the best";
  EXPECT_TRUE(p.columns[p.best_column].fits_as_well);
  EXPECT_GT(p.search.z_vs_nominal, 2.0);
  ASSERT_EQ(p.search.also.size(), 2u) << "the position is recorded with every point";
  EXPECT_EQ(p.search.also[0].knob, kPayloadX);
  EXPECT_EQ(p.search.also[0].value, p.x);
  EXPECT_GT(p.search.points.size(), 2u) << "two masses, then half-steps around the best";
}

TEST(PayloadSearch, ANominalRobotNamesNoPayload) {
  const Stages s = RunStages({}, 3);
  const PayloadSearch p = Search(s);
  ASSERT_TRUE(p.ran);
  EXPECT_FALSE(p.search.named) << "named " << p.search.value << " kg at " << p.x << ", " << p.y;
  EXPECT_FALSE(p.why.empty());
}

// The mass's half-steps can reach no payload at all (mass 0): the column's position is then the
// middle, not probe / 0 (the simulator refuses a position that is not a finite number).
TEST(PayloadSearch, AColumnRefinedDownToNoPayloadRecordsNoPosition) {
  const Stages s = RunStages({{kPayloadMass, 1.0}}, 3);  // two thirds of the mass probe, on the middle
  PayloadSearchOptions o;
  o.search.model = s.options.locate.model;
  o.forward = {0.0};
  o.sideways = {};
  const PayloadSearch p = SearchPayload(SharedFake(), s.in, s.set, s.options.candidates, o);
  ASSERT_TRUE(p.ran);
  ASSERT_TRUE(p.search.named) << p.why;
  bool zero = false;
  for (const LegSearchPoint& q : p.search.points) zero |= q.value == 0;
  EXPECT_TRUE(zero) << "the lighter mass fits best, and the half-steps go below it to 0";
  EXPECT_EQ(p.x, 0);
}

TEST(PayloadSearch, ANamedPayloadIsTheVerdictsOneStory) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  const PayloadSearch p = Search(s);
  ASSERT_TRUE(p.search.named);
  Verdict v = UnexplainedInRegions();
  AddPayloadSearch(p, &v);
  EXPECT_EQ(v.status, "partly_explained");
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "payload.mass_kg");
  EXPECT_EQ(v.named[0].family, "payload");
  EXPECT_EQ(v.sentence.find("Unexplained"), std::string::npos) << v.sentence;
  EXPECT_NE(v.sentence.find("behind the middle"), std::string::npos) << v.sentence;
  for (const std::string& d : v.doubts) EXPECT_EQ(d.find("regions"), std::string::npos) << "the old doubt stays: " << d;
}

// A challenge of knobs the probes named (PayloadSearchOptions::challenge_named): the payload replaces
// them only when its recording fits the real samples better than their correction; one that fits
// better by under the bar is a doubt of theirs, said with its mass and side.
TEST(PayloadSearch, AChallengedNameGivesWayOnlyToAPayloadThatFitsBetter) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  const std::vector<std::string> before = {"tracker.offset", "payload.mass_kg"};
  PayloadSearchOptions o;
  o.search.model = s.options.locate.model;
  PayloadSearch poor = Search(s);
  ASSERT_TRUE(poor.search.named) << poor.why;
  PayloadSearchChallenge(s.in, before, poor.search.nominal_model.LogLikelihood(s.in.real), o, &poor);
  EXPECT_TRUE(poor.search.named) << poor.why;
  EXPECT_GT(poor.search.z_vs_named, 2.0);
  Verdict v = UnexplainedInRegions();
  AddPayloadSearch(poor, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_NE(v.named[0].doubts[0].find("named tracker.offset and payload.mass_kg, which it fits"), std::string::npos)
      << v.named[0].doubts[0];
  EXPECT_NE(v.sentence.find("than the named knobs' correction (z"), std::string::npos) << v.sentence;

  PayloadSearch good = Search(s);
  PayloadSearchChallenge(s.in, before, good.search.best_rows.array() + 1.0, o, &good);
  EXPECT_FALSE(good.search.named);
  EXPECT_FALSE(good.search.rivals_named);
  EXPECT_NE(good.why.find("(a payload of "), std::string::npos) << "said as a payload, not a gain: " << good.why;
  EXPECT_NE(good.why.find("behind the middle) fits the real samples no better"), std::string::npos) << good.why;

  PayloadSearch rival;
  for (double t : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {  // corrections better at some placements, worse at others
    Eigen::VectorXd corrected = poor.search.best_rows;
    for (int i = 0; i < corrected.size(); ++i) corrected(i) += (s.in.real.episode[i] % 2 ? t : -t);
    rival = Search(s);
    PayloadSearchChallenge(s.in, before, corrected, o, &rival);
    if (rival.search.z_vs_named > 0 && rival.search.z_vs_named < o.search.z) break;
  }
  ASSERT_TRUE(rival.search.rivals_named) << rival.why;
  Verdict kept;
  kept.status = "explained";
  kept.sentence = "Simulator knobs and measurement effects, in order of evidence: (1) tracker_bias.";
  kept.named.resize(1);
  kept.named[0].knob = "tracker.offset";
  AddPayloadSearch(rival, &kept);
  ASSERT_EQ(kept.named.size(), 1u);
  EXPECT_EQ(kept.named[0].knob, "tracker.offset");
  EXPECT_EQ(kept.status, "partly_explained");
  ASSERT_EQ(kept.doubts.size(), 1u);
  EXPECT_NE(kept.doubts[0].find("behind the middle fits the real samples as well as the named knobs"), std::string::npos)
      << kept.doubts[0];
}

// A leg the leg search named, with its best point's scores `rows` (a LegSearch as SearchLegGains
// leaves it, the fields PayloadVersusLeg reads).
LegSearch NamedLeg(const Eigen::VectorXd& rows) {
  LegSearch leg;
  leg.ran = leg.named = true;
  leg.leg = "leg3";
  leg.knob = "actuators.leg3.gain";
  leg.value = 0.45;
  leg.best_rows = rows;
  leg.points = {{"leg3", leg.knob, kLeg3Gain, leg.value, rows.mean(), true}};
  leg.best = 0;
  return leg;
}

// Scores per real sample `shift` nats above `rows`, spread by a tenth of a nat across placements.
Eigen::VectorXd Shifted(const Eigen::VectorXd& rows, const std::vector<int>& placement, double shift) {
  Eigen::VectorXd out = rows;
  for (int i = 0; i < out.size(); ++i) out(i) += shift + 0.1 * (placement[i] % 3 - 1);
  return out;
}

// A payload off the middle can pass for one weak leg (PayloadVersusLeg): the payload that fits
// better by the bar takes the leg's name, one that fits worse leaves it, one in between is a doubt.
TEST(PayloadSearch, APayloadThatFitsBetterThanANamedLegTakesItsName) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  PayloadSearchOptions o;
  const PayloadSearch found = Search(s);
  ASSERT_TRUE(found.search.named) << found.why;
  const std::vector<int>& placement = s.in.real.episode;

  PayloadSearch better = found;
  LegSearch worse_leg = NamedLeg(Shifted(found.search.best_rows, placement, -1.0));
  PayloadVersusLeg(s.in, o, &worse_leg, &better);
  EXPECT_TRUE(better.search.named);
  EXPECT_FALSE(worse_leg.named);
  EXPECT_GT(better.search.z_vs_named, o.search.z);
  EXPECT_NE(worse_leg.why.find("(leg3 at gain 0.45) fits the real samples worse than a payload of"), std::string::npos)
      << worse_leg.why;
  Verdict v = UnexplainedInRegions();
  AddLegSearch(worse_leg, &v);
  AddPayloadSearch(better, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "payload.mass_kg");
  EXPECT_NE(v.named[0].doubts[0].find("after the leg search named a weak leg3 leg (gain 0.45), which it fits"),
            std::string::npos)
      << v.named[0].doubts[0];
  EXPECT_NE(v.sentence.find("than the weak leg3 leg (gain 0.45) the leg search named (z"), std::string::npos) << v.sentence;

  PayloadSearch worse = found;
  LegSearch better_leg = NamedLeg(Shifted(found.search.best_rows, placement, 1.0));
  PayloadVersusLeg(s.in, o, &better_leg, &worse);
  EXPECT_TRUE(better_leg.named);
  EXPECT_FALSE(worse.search.named);
  EXPECT_FALSE(worse.search.rivals_named);
  EXPECT_NE(worse.why.find("fits the real samples no better than the weak leg3 leg"), std::string::npos) << worse.why;

  PayloadSearch rival = found;
  LegSearch close_leg = NamedLeg(Shifted(found.search.best_rows, placement, -0.01));
  PayloadVersusLeg(s.in, o, &close_leg, &rival);
  ASSERT_GT(rival.search.z_vs_named, 0);
  ASSERT_LT(rival.search.z_vs_named, o.search.z);
  EXPECT_TRUE(close_leg.named);
  EXPECT_FALSE(rival.search.named);
  EXPECT_TRUE(rival.search.rivals_named);
  Verdict kept = UnexplainedInRegions();
  AddLegSearch(close_leg, &kept);
  AddPayloadSearch(rival, &kept);
  ASSERT_EQ(kept.named.size(), 1u);
  EXPECT_EQ(kept.named[0].knob, "actuators.leg3.gain");
  EXPECT_EQ(kept.status, "partly_explained");
  bool doubted = false;
  for (const std::string& d : kept.doubts) doubted |= d.find("fits the real samples as well as the named") != std::string::npos;
  EXPECT_TRUE(doubted) << kept.sentence;
}

// A payload its own gates refused takes no name from a leg, but where it fits the real samples
// better by the bar the leg's name is doubted in the verdict; one that fits worse changes nothing.
TEST(PayloadSearch, ARefusedPayloadThatFitsBetterDoubtsTheNamedLeg) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  PayloadSearchOptions o;
  PayloadSearch refused = Search(s);
  ASSERT_TRUE(refused.search.named) << refused.why;
  refused.search.named = false;
  refused.why = "its best mass sits at the search's upper limit";
  const std::vector<int>& placement = s.in.real.episode;

  PayloadSearch better = refused;
  LegSearch worse_leg = NamedLeg(Shifted(refused.search.best_rows, placement, -1.0));
  PayloadVersusLeg(s.in, o, &worse_leg, &better);
  EXPECT_TRUE(worse_leg.named);
  EXPECT_FALSE(better.search.named);
  EXPECT_TRUE(better.refused_fits_better);
  EXPECT_GT(better.search.z_vs_named, o.search.z);
  Verdict v = UnexplainedInRegions();
  AddLegSearch(worse_leg, &v);
  ASSERT_EQ(v.named.size(), 1u);
  v.status = "explained";
  AddPayloadSearch(better, &v);
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "actuators.leg3.gain");
  EXPECT_EQ(v.status, "partly_explained");
  bool doubted = false;
  for (const std::string& d : v.doubts) {
    doubted |= d.find("better than the weak leg3 leg (gain 0.45) the leg search named") != std::string::npos &&
               d.find("though its own gates refused it (its best mass sits at the search's upper limit)") != std::string::npos;
  }
  EXPECT_TRUE(doubted) << v.sentence;

  PayloadSearch worse = refused;
  LegSearch better_leg = NamedLeg(Shifted(refused.search.best_rows, placement, 1.0));
  PayloadVersusLeg(s.in, o, &better_leg, &worse);
  EXPECT_FALSE(worse.refused_fits_better);
  EXPECT_TRUE(worse.leg_challenged.empty());
  Verdict kept = UnexplainedInRegions();
  AddLegSearch(better_leg, &kept);
  kept.status = "explained";
  const std::size_t doubts = kept.doubts.size();
  AddPayloadSearch(worse, &kept);
  EXPECT_EQ(kept.status, "explained");
  EXPECT_EQ(kept.doubts.size(), doubts);
}

// On the fake's planted weak leg both searches run on the real samples: the leg fits better and
// keeps its name.
TEST(PayloadSearch, APlantedWeakLegKeepsItsNameAgainstThePayload) {
  const Stages s = RunStages({{kLeg1Gain, 0.38}}, 3);
  LegSearchOptions lo;
  lo.model = s.options.locate.model;
  LegSearch leg = SearchLegGains(SharedFake(), s.in, s.set, s.options.candidates, lo);
  ASSERT_TRUE(leg.named) << leg.why;
  PayloadSearch p = Search(s);
  PayloadVersusLeg(s.in, PayloadSearchOptions{}, &leg, &p);
  EXPECT_TRUE(leg.named) << leg.why;
  EXPECT_EQ(leg.leg, "leg1");
  EXPECT_FALSE(p.search.named) << p.why;
}

// Where several columns fit as well, the torso's posture (PostureLeft) chooses among them; a
// column that fits worse, or a posture that cannot be checked, changes nothing.
TEST(PayloadSearch, ThePostureChoosesAmongTheColumnsThatFitAsWell) {
  const Stages s = RunStages({{kPayloadMass, 2.4}, {kPayloadX, -0.1}}, 3);
  const PayloadSearch alone = Search(s);
  std::vector<int> as_well, worse;
  for (int j = 0; j < static_cast<int>(alone.columns.size()); ++j) {
    if (j == alone.best_column) continue;
    (alone.columns[j].fits_as_well ? as_well : worse).push_back(j);
  }
  ASSERT_FALSE(as_well.empty()) << "the fake's payload acts by its moment: columns near the best fit as well";
  ASSERT_FALSE(worse.empty());
  // A posture that only the column `pick` gives (columns told apart by where they place the mass).
  auto search_with = [&](int pick, double at_pick) {
    PayloadSearchOptions o;
    o.search.model = s.options.locate.model;
    o.posture_chooses = true;  // off by default
    const PayloadColumn& c = alone.columns[pick];
    const PostureLeft posture = [&c, at_pick](const std::vector<KnobValue>& values) {
      for (const KnobValue& v : values) {
        if (v.knob == kPayloadX && v.value == c.best_x) return at_pick;
      }
      return 3.0;
    };
    return SearchPayload(SharedFake(), s.in, s.set, s.options.candidates, o, posture);
  };
  const PayloadSearch chosen = search_with(as_well[0], 0.5);
  EXPECT_EQ(chosen.likelihood_best, alone.best_column);
  EXPECT_EQ(chosen.best_column, as_well[0]);
  EXPECT_DOUBLE_EQ(chosen.columns[as_well[0]].posture_z, 0.5);
  EXPECT_DOUBLE_EQ(chosen.columns[alone.best_column].posture_z, 3.0);
  EXPECT_TRUE(std::isnan(chosen.columns[worse[0]].posture_z)) << "only the columns that fit as well are checked";
  Verdict v = UnexplainedInRegions();
  AddPayloadSearch(chosen, &v);
  EXPECT_NE(v.sentence.find("the torso's posture chose"), std::string::npos) << v.sentence;
  EXPECT_EQ(search_with(worse[0], 0.5).best_column, alone.best_column) << "a column that fits worse";
  EXPECT_EQ(search_with(as_well[0], NAN).best_column, alone.best_column) << "a posture not checked";
  PayloadSearchOptions by_default;
  by_default.search.model = s.options.locate.model;
  EXPECT_FALSE(by_default.posture_chooses) << "off by default since 2026-12-08";
  EXPECT_EQ(SearchPayload(SharedFake(), s.in, s.set, s.options.candidates, by_default,
                          [](const std::vector<KnobValue>&) { return 0.5; })
                .best_column,
            alone.best_column)
      << "off, the posture checks nothing";
  Verdict plain = UnexplainedInRegions();
  AddPayloadSearch(alone, &plain);
  EXPECT_EQ(plain.sentence.find("posture chose"), std::string::npos) << plain.sentence;
}

// A column the posture chose that, refined, fits no better than the nominal gives way to the
// likelihood's best (on a nominal robot nothing is named either way).
TEST(PayloadSearch, APostureChoiceThatNamesNothingGivesWayToTheLikelihoodsBest) {
  const Stages s = RunStages({}, 3);
  const PayloadSearch alone = Search(s);
  int other = -1;
  for (int j = 0; j < static_cast<int>(alone.columns.size()); ++j) {
    if (j != alone.best_column && alone.columns[j].fits_as_well) other = j;
  }
  ASSERT_GE(other, 0);
  PayloadSearchOptions o;
  o.search.model = s.options.locate.model;
  o.posture_chooses = true;
  const double x = alone.columns[other].best_x, y = alone.columns[other].best_y;
  const PayloadSearch p = SearchPayload(SharedFake(), s.in, s.set, s.options.candidates, o,
                                        [x, y](const std::vector<KnobValue>& values) {
                                          return values.at(1).value == x && values.at(2).value == y ? 0.1 : 3.0;
                                        });
  EXPECT_DOUBLE_EQ(p.columns[other].posture_z, 0.1);
  EXPECT_FALSE(p.search.named);
  EXPECT_EQ(p.best_column, alone.best_column);
  EXPECT_EQ(p.search.value, alone.search.value);
}

// In the analysis: off by default; when enabled it runs on physics no knob describes (nothing named
// by the probes or the leg search; or a name the leg search challenged), names no payload there,
// and the report has it.
TEST(PayloadSearch, RunsInTheAnalysisOnlyWhenEnabledAndNothingIsNamed) {
  FakeExtras extras;
  extras.geometry = 0.03;
  const FakePair pair = MakeFakePair(SharedFake(), {}, extras);
  AnalysisOptions options = FastOptions();
  EXPECT_TRUE(options.payload.enabled) << "on by default";
  options.payload.enabled = false;
  EXPECT_FALSE(Analyse(pair.sim, pair.real, &SharedFake(), options).payload_search.ran);
  options.payload.enabled = true;
  const Analysis a = Analyse(pair.sim, pair.real, &SharedFake(), options);
  ASSERT_TRUE(a.naming.named.empty() && !a.leg_search.named) << a.verdict.sentence;
  ASSERT_TRUE(a.payload_search.ran) << a.verdict.sentence;
  EXPECT_FALSE(a.payload_search.search.named) << a.verdict.sentence;
  EXPECT_NE(a.verdict.sentence.find("A search of a payload's mass and position"), std::string::npos) << a.verdict.sentence;
  EXPECT_EQ(Analyse(pair.sim, pair.real, &SharedFake(), options).verdict.sentence, a.verdict.sentence)
      << "the same answer twice";
  const auto friction = MakeFakePair(SharedFake(), {{kFriction, 0.6}});
  const Analysis with_name = Analyse(friction.sim, friction.real, &SharedFake(), options);
  ASSERT_FALSE(with_name.naming.named.empty()) << with_name.verdict.sentence;
  EXPECT_FALSE(with_name.payload_search.ran) << "something was named and not challenged";
}

}  // namespace
}  // namespace dgmm::sim2real::test
