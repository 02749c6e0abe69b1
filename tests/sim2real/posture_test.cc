// The torso's posture beside the motion (posture.h): the shift of mean z between two sets, and in
// the whole analysis on the fake's level ground a named correction that gives the real posture
// (a weak side tilts the fake's roll) against one that leaves a tilt out; on a slope no check.
#include "sim2real/posture.h"

#include <gtest/gtest.h>

#include "sim2real/analysis.h"
#include "tests/sim2real/fake_simulator.h"

namespace dgmm::sim2real::test {
namespace {

const FakeSimulator& LevelFake() {
  static const FakeSimulator* fake = [] {
    auto* f = new FakeSimulator();
    f->level = true;
    return f;
  }();
  return *fake;
}

Analysis RunLevel(const std::vector<KnobValue>& planted, const FakeExtras& extras = {}) {
  const FakePair pair = MakeFakePair(LevelFake(), planted, extras);
  return Analyse(pair.sim, pair.real, &LevelFake(), FastOptions());
}

bool SaysPosture(const Verdict& v) {
  for (const std::string& d : v.doubts) {
    if (d.find("posture") != std::string::npos) return true;
  }
  return false;
}

TEST(Posture, TheShiftOfMeanZIsMeasuredWithItsError) {
  const FakeSimulator& fake = LevelFake();
  Recording r;
  r.protocol = "paper";
  r.seed = 3;
  const SampleSet sim = fake.Record(r, {}, 1);
  r.seed = 4;
  FakeExtras tilt;
  tilt.posture = Eigen::Vector2d(0.01, -0.02);
  const SampleSet real = fake.RecordWith(r, {}, tilt);
  const PostureShift d = MeasurePostureShift(real, sim, 0, 1, false, 100, 5);
  ASSERT_TRUE(d.se.allFinite());
  EXPECT_GT(d.se.minCoeff(), 0);
  EXPECT_LT(d.se.maxCoeff(), 0.005) << "72 placements of 5 executions, 0.02 rad noise";
  EXPECT_NEAR(d.shift(0), 0.01, 4 * d.se(0));
  EXPECT_NEAR(d.shift(1), -0.02, 4 * d.se(1));
  const PostureShift first = MeasurePostureShift(real, sim, 0, 1, true, 100, 5);
  EXPECT_GT(first.se(0), d.se(0)) << "one execution of each placement: a wider error";
  EXPECT_EQ(MeasurePostureShift(real, sim, 0, 1, false, 100, 5).se, d.se) << "seeded";
}

TEST(Posture, ARecordingAtTheSamePlacesIsComparedPairwise) {
  const FakeSimulator& fake = LevelFake();
  Recording r;
  r.protocol = "paper";
  r.seed = 3;
  const SampleSet nominal = fake.Record(r, {}, 1), weak = fake.Record(r, {{kRightGain, 0.5}}, 1);
  const PostureShift paired = MeasurePairedPostureShift(weak, nominal, 0, 1, false, 100, 5);
  const PostureShift unpaired = MeasurePostureShift(weak, nominal, 0, 1, false, 100, 5);
  EXPECT_NEAR(paired.shift(1), 0.02, 0.002) << "0.04 (1 - 0.5) of roll";
  EXPECT_NEAR(paired.shift(1), unpaired.shift(1), 1e-12) << "the same rows, the same means";
  EXPECT_LT(paired.se(1), 0.8 * unpaired.se(1)) << "resampled jointly: the shared placements' noise cancels";
}

TEST(Posture, ACorrectionThatGivesTheTiltLeavesNoDoubt) {
  const Analysis a = RunLevel({{kRightGain, 0.5}});
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  ASSERT_FALSE(a.verdict.named.empty()) << a.verdict.sentence;
  EXPECT_GT(a.posture.z_moved, 4) << "the weak right side rolls the fake";
  EXPECT_TRUE(a.posture.recorded);
  EXPECT_FALSE(a.posture.left_out) << "left " << a.posture.left.transpose() << " z " << a.posture.z_left;
  EXPECT_FALSE(SaysPosture(a.verdict)) << a.verdict.sentence;
}

TEST(Posture, ATiltNoNamedKnobGivesIsADoubt) {
  FakeExtras extras;
  extras.posture = Eigen::Vector2d(0.02, 0);
  const Analysis a = RunLevel({{kRightGain, 0.5}}, extras);
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_TRUE(a.posture.left_out) << "left " << a.posture.left.transpose() << " z " << a.posture.z_left;
  EXPECT_NEAR(a.posture.left(0), 0.02, 0.006);
  EXPECT_NE(a.verdict.status, "explained") << a.verdict.sentence;
  EXPECT_NE(a.verdict.status, "clean") << a.verdict.sentence;
  ASSERT_TRUE(SaysPosture(a.verdict)) << a.verdict.sentence;
  EXPECT_NE(a.verdict.sentence.find("IMU mounted off level"), std::string::npos)
      << "the fake's tilt moves the standing posture alike: " << a.verdict.sentence;
}

TEST(Posture, ANullPairOnLevelGroundStaysClean) {
  const Analysis a = RunLevel({});
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_FALSE(a.posture.left_out) << a.posture.z_left;
  EXPECT_FALSE(a.posture.recorded) << "nothing named: nothing to record";
  EXPECT_EQ(a.verdict.status, "clean") << a.verdict.sentence;
}

TEST(Posture, NoCheckOnASlopeOrWhenTurnedOff) {
  FakeSimulator sloped;
  const FakePair pair = MakeFakePair(sloped, {{kRightGain, 0.5}});
  const Analysis a = Analyse(pair.sim, pair.real, &sloped, FastOptions());
  EXPECT_FALSE(a.posture.ran);
  EXPECT_NE(a.posture.why.find("not level"), std::string::npos) << a.posture.why;
  AnalysisOptions off = FastOptions();
  off.posture.enabled = false;
  const FakePair level = MakeFakePair(LevelFake(), {{kRightGain, 0.5}});
  EXPECT_FALSE(Analyse(level.sim, level.real, &LevelFake(), off).posture.ran);
}

}  // namespace
}  // namespace dgmm::sim2real::test
