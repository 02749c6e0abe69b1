// The torso's posture beside the motion (posture.h): the shift of mean z between two sets, and in
// the whole analysis on the fake's level ground a named correction that gives the real posture
// (a weak side tilts the fake's roll) against one that leaves a tilt out; on a sloped plane the
// radial part of z; on uneven ground no check; where the analysis only locates, the real posture
// against the sim set's alone.
#include "sim2real/posture.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "sim2real/analysis.h"
#include "tests/sim2real/fake_simulator.h"

namespace dgmm::sim2real::test {
namespace {

// One fake per call site, configured once (a test's recordings stay cached by its fingerprint).
template <typename Configure>
const FakeSimulator& StaticFake(Configure configure) {
  static const FakeSimulator* fake = [&] {
    auto* f = new FakeSimulator();
    configure(f);
    return f;
  }();
  return *fake;
}

const FakeSimulator& LevelFake() {
  return StaticFake([](FakeSimulator* f) { f->level = true; });
}

// Level ground whose z spreads 0.1 rad about the posture and whose tilt steers the walk: x's slope
// in z, through which the probes read an IMU offset, is measurable.
const FakeSimulator& SpreadLevelFake() {
  return StaticFake([](FakeSimulator* f) {
    f->level = true;
    f->level_z_sd = 0.1;
    f->tilt_steers = 0.5;
  });
}

Analysis RunLevel(const std::vector<KnobValue>& planted, const FakeExtras& extras = {}) {
  const FakePair pair = MakeFakePair(LevelFake(), planted, extras);
  return Analyse(pair.sim, pair.real, &LevelFake(), FastOptions());
}

// The paper protocol's recording with common random numbers `seed`.
Recording PaperAt(std::uint64_t seed) {
  Recording r;
  r.protocol = "paper";
  r.seed = seed;
  return r;
}

// The fake's recording at seed `seed`, nothing planted.
SampleSet RecordAt(const FakeSimulator& fake, std::uint64_t seed) { return fake.Record(PaperAt(seed), {}, 1); }

bool SaysPosture(const Verdict& v) {
  for (const std::string& d : v.doubts) {
    if (d.find("posture") != std::string::npos) return true;
  }
  return false;
}

TEST(Posture, TheShiftOfMeanZIsMeasuredWithItsError) {
  const FakeSimulator& fake = LevelFake();
  const SampleSet sim = RecordAt(fake, 3);
  FakeExtras tilt;
  tilt.posture = Eigen::Vector2d(0.01, -0.02);
  const SampleSet real = fake.RecordWith(PaperAt(4), {}, tilt);
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
  const SampleSet nominal = RecordAt(fake, 3), weak = fake.Record(PaperAt(3), {{kRightGain, 0.5}}, 1);
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

bool Names(const Verdict& v, const std::string& knob) {
  for (const VerdictNamed& n : v.named) {
    if (n.knob == knob) return true;
  }
  return false;
}

// The motion as the torso tilted by (0.1, -0.08) rad more than the recorded z says would give it: an
// IMU offset in x given z. With `in_the_imu_too` it is one (the recorded z moved); else the recorded z
// is what the torso does.
FakeExtras ImuOffsetInTheMotion(bool in_the_imu_too) {
  FakeExtras extras;
  const Eigen::Vector2d b(0.1, -0.08);
  (in_the_imu_too ? extras.imu_offset : extras.motion_tilt) = in_the_imu_too ? b : Eigen::Vector2d(-b);
  return extras;
}

TEST(Posture, ANamedImuOffsetThePostureContradictsIsFittedAgainWithoutIt) {
  const FakeSimulator& fake = SpreadLevelFake();
  const FakePair pair = MakeFakePair(fake, {{kRightGain, 0.5}}, ImuOffsetInTheMotion(false));
  AnalysisOptions keep = FastOptions();
  keep.posture.refit_without_imu = false;
  const Analysis kept = Analyse(pair.sim, pair.real, &fake, keep);
  ASSERT_TRUE(Names(kept.verdict, "imu.pitch_roll_offset")) << "the motion reads as one: " << kept.verdict.sentence;
  ASSERT_TRUE(kept.posture.left_out) << "the recorded z did not move: " << kept.posture.z_left;
  EXPECT_FALSE(kept.imu_contradicted.refitted);
  EXPECT_NE(kept.verdict.sentence.find("the offset is not what the IMU reads"), std::string::npos)
      << kept.verdict.sentence;

  const Analysis a = Analyse(pair.sim, pair.real, &fake, FastOptions());
  ASSERT_TRUE(a.imu_contradicted.refitted) << a.verdict.sentence;
  EXPECT_EQ(a.imu_contradicted.check.imu, kept.posture.imu) << "the first fit is the run without the refit";
  EXPECT_FALSE(Names(a.verdict, "imu.pitch_roll_offset")) << a.verdict.sentence;
  EXPECT_TRUE(Names(a.verdict, "actuators.side.right.gain")) << a.verdict.sentence;
  EXPECT_EQ(a.posture.imu, Eigen::Vector2d::Zero());
  EXPECT_FALSE(a.posture.left_out) << a.posture.z_left;
  EXPECT_NE(a.verdict.sentence.find("ran again without an IMU offset"), std::string::npos) << a.verdict.sentence;
  EXPECT_GT(a.candidates.requests, kept.candidates.requests) << "both runs' recordings are counted";
}

// The same motion with the recorded z moved by the offset: the posture bears the offset out (its
// size may differ from the fit's: the fake's weak side rolls the torso too).
TEST(Posture, AnImuOffsetThePostureBearsOutStaysNamed) {
  const FakePair pair = MakeFakePair(SpreadLevelFake(), {{kRightGain, 0.5}}, ImuOffsetInTheMotion(true));
  const Analysis a = Analyse(pair.sim, pair.real, &SpreadLevelFake(), FastOptions());
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_TRUE(Names(a.verdict, "imu.pitch_roll_offset")) << a.verdict.sentence;
  EXPECT_GE(a.posture.z_left_without_imu, 4) << "the real z moved: without the offset the posture is further off";
  EXPECT_LT(a.posture.z_left, a.posture.z_left_without_imu);
  EXPECT_FALSE(a.imu_contradicted.refitted);
}

TEST(Posture, ANullPairOnLevelGroundStaysClean) {
  const Analysis a = RunLevel({});
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_FALSE(a.posture.left_out) << a.posture.z_left;
  EXPECT_FALSE(a.posture.recorded) << "nothing named: nothing to record";
  EXPECT_EQ(a.verdict.status, "clean") << a.verdict.sentence;
}

const FakeSimulator& SlopedPlaneFake() {
  return StaticFake([](FakeSimulator* f) { f->sloped_plane = true; });
}

// The fake's 0.3 rad slope: z on a circle around the posture, the heading's place on it.
TEST(Posture, OnASlopeTheShiftComesFromTheRadialPartOfZ) {
  const FakeSimulator& fake = SlopedPlaneFake();
  const SampleSet sim = RecordAt(fake, 3);
  const SlopeGeometry g = FitSlopeGeometry(sim, 0, 1);
  ASSERT_TRUE(g.valid) << g.why;
  EXPECT_NEAR(g.radius(0), 0.3, 0.01);
  EXPECT_LT(g.centre.norm(), 0.01);
  FakeExtras tilt;
  tilt.posture = Eigen::Vector2d(0.01, -0.02);
  const SampleSet real = fake.RecordWith(PaperAt(4), {}, tilt), null = RecordAt(fake, 4);
  const PostureShift d = MeasurePostureShift(real, sim, 0, 1, false, 100, 5, &g);
  ASSERT_TRUE(d.se.allFinite());
  EXPECT_LT(d.se.maxCoeff(), 0.005);
  EXPECT_NEAR(d.shift(0), 0.01, 4 * d.se(0));
  EXPECT_NEAR(d.shift(1), -0.02, 4 * d.se(1));
  const PostureShift zero = MeasurePostureShift(null, sim, 0, 1, false, 100, 5, &g);
  EXPECT_LT(std::abs(zero.shift(0)), 4 * zero.se(0));
  EXPECT_LT(std::abs(zero.shift(1)), 4 * zero.se(1));
}

// A robot that ends its executions at other headings (a turn that went further) reads z further
// along the circle: no posture. Plain means per command are no measure there: they spread with the
// placements' headings.
TEST(Posture, MovingAlongTheSlopesCircleIsNoPostureShift) {
  const SampleSet sim = RecordAt(SlopedPlaneFake(), 3);
  SampleSet turned = RecordAt(SlopedPlaneFake(), 4);
  const Eigen::Rotation2Dd along(0.15);  // the executions at headings on one side of the slope
  for (int i = 0; i < turned.size(); ++i) {
    if (turned.z(i, 1) > 0) turned.z.row(i) = (along * Eigen::Vector2d(turned.z.row(i).transpose())).transpose();
  }
  const SlopeGeometry g = FitSlopeGeometry(sim, 0, 1);
  const PostureShift radial = MeasurePostureShift(turned, sim, 0, 1, false, 100, 5, &g);
  EXPECT_LT(std::abs(radial.shift(0)), 4 * radial.se(0)) << radial.shift.transpose();
  EXPECT_LT(std::abs(radial.shift(1)), 4 * radial.se(1)) << radial.shift.transpose();
  EXPECT_LT(radial.shift.norm(), 0.005) << "those executions moved 0.045 rad along the circle";
  const PostureShift means = MeasurePostureShift(turned, sim, 0, 1, false, 100, 5);
  EXPECT_LT(radial.se.maxCoeff(), 0.2 * means.se.minCoeff()) << "plain means spread with the placements' headings";
}

// A placement whose robot tipped over reads z far off the circle: left out, no posture.
TEST(Posture, OnASlopeATippedExecutionIsNoPosture) {
  const SampleSet sim = RecordAt(SlopedPlaneFake(), 3);
  SampleSet tipped = RecordAt(SlopedPlaneFake(), 4);
  for (int i = 1; i < 5; ++i) tipped.z.row(i) *= 3;  // 0.6 rad further out after its first execution
  const SlopeGeometry g = FitSlopeGeometry(sim, 0, 1);
  EXPECT_LT(g.outlier_rad, 0.2);
  const PostureShift d = MeasurePostureShift(tipped, sim, 0, 1, false, 100, 5, &g);
  EXPECT_LT(d.shift.norm(), 0.005) << d.shift.transpose();
  EXPECT_LT(d.se.maxCoeff(), 0.005);
}

TEST(Posture, ZOffTheSlopesCircleHasNoGeometry) {
  const SlopeGeometry g = FitSlopeGeometry(RecordAt(LevelFake(), 3), 0, 1);
  EXPECT_FALSE(g.valid);
  EXPECT_NE(g.why.find("circle"), std::string::npos) << g.why;
}

TEST(Posture, OnASlopedPlaneATiltNoNamedKnobGivesIsADoubt) {
  const FakeSimulator& fake = SlopedPlaneFake();
  const FakePair weak = MakeFakePair(fake, {{kRightGain, 0.5}});
  const Analysis a = Analyse(weak.sim, weak.real, &fake, FastOptions());
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_TRUE(a.posture.on_slope);
  EXPECT_FALSE(a.posture.left_out) << "the weak side's roll is the correction's: z " << a.posture.z_left;
  FakeExtras extras;
  extras.posture = Eigen::Vector2d(0.02, 0);
  const FakePair tilted = MakeFakePair(fake, {{kRightGain, 0.5}}, extras);
  const Analysis b = Analyse(tilted.sim, tilted.real, &fake, FastOptions());
  ASSERT_TRUE(b.posture.ran) << b.posture.why;
  EXPECT_TRUE(b.posture.left_out) << "left " << b.posture.left.transpose() << " z " << b.posture.z_left;
  EXPECT_NEAR(b.posture.left(0), 0.02, 0.006);
  EXPECT_TRUE(SaysPosture(b.verdict)) << b.verdict.sentence;
}

TEST(Posture, NoCheckOnUnevenGroundOrWhenTurnedOff) {
  FakeSimulator uneven;  // the fake's slope, not declared a plane
  const FakePair pair = MakeFakePair(uneven, {{kRightGain, 0.5}});
  const Analysis a = Analyse(pair.sim, pair.real, &uneven, FastOptions());
  EXPECT_FALSE(a.posture.ran);
  EXPECT_NE(a.posture.why.find("not a plane"), std::string::npos) << a.posture.why;
  AnalysisOptions off = FastOptions();
  off.posture.enabled = false;
  const FakePair level = MakeFakePair(LevelFake(), {{kRightGain, 0.5}});
  EXPECT_FALSE(Analyse(level.sim, level.real, &LevelFake(), off).posture.ran);
}

// Located only (no simulator): the real posture against the sim set's, the ground as the config
// gives it.
AnalysisOptions LocatedOn(PostureGround ground) {
  AnalysisOptions o = FastOptions();
  o.posture.ground = ground;
  return o;
}
constexpr PostureGround kLevel{true, true, true}, kSlope{true, true, false};

// A pair on `fake` whose real robot sits 0.02 rad nose down, located only on `ground`.
Analysis LocateTilted(const FakeSimulator& fake, PostureGround ground) {
  FakeExtras tilt;
  tilt.posture = Eigen::Vector2d(0.02, 0);
  const FakePair pair = MakeFakePair(fake, {}, tilt);
  return Analyse(pair.sim, pair.real, nullptr, LocatedOn(ground), "no simulator config");
}

TEST(Posture, WhereTheAnalysisOnlyLocatesATiltedRealRobotIsALocatedMismatch) {
  const Analysis a = LocateTilted(LevelFake(), kLevel);
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_TRUE(a.posture.compared_only);
  EXPECT_FALSE(a.posture.recorded);
  EXPECT_TRUE(a.posture.left_out) << a.posture.z_moved;
  EXPECT_NEAR(a.posture.walking.shift(0), 0.02, 0.006);
  EXPECT_EQ(a.verdict.status, "located") << a.verdict.sentence;
  EXPECT_NE(std::find(a.verdict.structured_in.begin(), a.verdict.structured_in.end(), "posture"),
            a.verdict.structured_in.end());
  EXPECT_NE(a.verdict.sentence.find("The posture: "), std::string::npos) << a.verdict.sentence;
  EXPECT_TRUE(a.verdict.named.empty());
  const FakePair null = MakeFakePair(LevelFake(), {});
  const Analysis b = Analyse(null.sim, null.real, nullptr, LocatedOn(kLevel), "no simulator config");
  ASSERT_TRUE(b.posture.ran) << b.posture.why;
  EXPECT_FALSE(b.posture.left_out) << b.posture.z_moved;
  EXPECT_EQ(b.verdict.sentence.find("The posture: "), std::string::npos) << b.verdict.sentence;
}

TEST(Posture, LocatedOnlyOnASlopeTheRadialPartCompares) {
  const Analysis a = LocateTilted(SlopedPlaneFake(), kSlope);
  ASSERT_TRUE(a.posture.ran) << a.posture.why;
  EXPECT_TRUE(a.posture.on_slope);
  EXPECT_NEAR(a.posture.walking.shift(0), 0.02, 0.006);
  EXPECT_TRUE(a.posture.left_out);
  const Analysis flat = LocateTilted(SlopedPlaneFake(), kLevel);
  EXPECT_GT(flat.posture.walking.se(0), 5 * a.posture.walking.se(0))
      << "a slope taken for level ground: plain means spread with the headings";
}

TEST(Posture, LocatedOnlyWithoutAGroundThePostureIsNotCompared) {
  const FakePair pair = MakeFakePair(LevelFake(), {});
  const Analysis a = Analyse(pair.sim, pair.real, nullptr, FastOptions(), "no simulator config");
  EXPECT_FALSE(a.posture.ran);
  EXPECT_NE(a.posture.why.find("not known"), std::string::npos) << a.posture.why;
  const Analysis b = Analyse(pair.sim, pair.real, nullptr, LocatedOn({true, false, false}), "no simulator config");
  EXPECT_NE(b.posture.why.find("not a plane"), std::string::npos) << b.posture.why;
}

// On a slope the correction's recording compares with the nominal's on the nominal's own circle:
// needed only when something is recorded.
TEST(Posture, TheNominalsCircleIsNeededOnlyForARecordedCorrection) {
  const FakeSimulator& fake = SlopedPlaneFake();
  const FakePair pair = MakeFakePair(fake, {});
  const AnalysisInputs in = PrepareInputs(pair.sim, pair.real, 1);
  const SampleSet off_circle = RecordAt(LevelFake(), 3);
  const RecordingOptions recording = FastOptions().candidates.recording;
  const PostureCheck nothing = CheckPosture(fake, in, off_circle, PaperAt(3), recording, {}, Eigen::Vector2d::Zero(),
                                            "nothing named", PostureOptions());
  EXPECT_TRUE(nothing.ran) << nothing.why;
  const PostureCheck weak = CheckPosture(fake, in, off_circle, PaperAt(3), recording, {{kRightGain, 0.5}},
                                         Eigen::Vector2d::Zero(), "weak", PostureOptions());
  EXPECT_FALSE(weak.ran);
  EXPECT_NE(weak.why.find("nominal recording"), std::string::npos) << weak.why;
}

}  // namespace
}  // namespace dgmm::sim2real::test
