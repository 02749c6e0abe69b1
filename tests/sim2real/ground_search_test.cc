// The ground's standing tilt (ground_search.h) on a fake of its own: a robot on a sloped height
// field whose standing tilt spreads with the ground's roughness (a Gaussian about the slope's
// circle) and with its boulders' height (a few placements tilted far), and whose motion spreads
// with the roughness. A rougher real ground is named with its value, on the slope's circle even where
// the ground's tilts blur it; a null moves nothing; a spread no ground knob reaches, or a ground
// without knobs, names nothing and says why.
#include "sim2real/ground_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim2real/candidates.h"
#include "sim2real/inputs.h"
#include "sim2real/posture.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real::test {
namespace {

enum GroundFakeKnob { kRough = 0, kStones = 1 };

Knob GroundKnob(const std::string& name) {
  Knob k;
  k.name = name, k.family = "ground", k.nominal = 1, k.lo = 0, k.hi = 3, k.physical_min = 0, k.probes = {0.5, 1.5};
  return k;
}

class GroundFake : public KnobSimulator {
 public:
  explicit GroundFake(bool with_knobs = true) {
    if (with_knobs) knobs_ = {GroundKnob("terrain.rough.rms_scale"), GroundKnob("terrain.stones.height_scale")};
  }
  const std::vector<Knob>& knobs() const override { return knobs_; }
  std::string Fingerprint() const override { return "ground-fake-v1"; }
  SampleSet Record(const Recording& recording, const std::vector<KnobValue>& values, int) const override {
    double rough = 1, stones = 1;
    for (const KnobValue& v : values) (v.knob == kRough ? rough : stones) = v.value;
    return RecordAt(recording, rough * extra_roughness, stones);
  }
  CellRecording RecordCell(const Cell&, const std::vector<KnobValue>&) const override { return {}; }
  std::string ConfigJson(const std::vector<KnobValue>&) const override { return "{}"; }
  double total_mass_kg() const override { return 10; }
  double leg_reach_m() const override { return 0.3; }
  bool sloped_ground() const override { return sloped; }
  // The "real" ground's roughness beyond what the knob gives (a factor on every recording).
  double extra_roughness = 1;
  double tilt_sd = 0.01;  // the standing tilt's SD per axis at roughness 1 (rad; the slope's circle 0.17)
  bool sloped = false;    // does the simulator say its ground is sloped?

 private:
  // Placement p of recording seed s: a heading, a command, a standing tilt; then its executions.
  SampleSet RecordAt(const Recording& recording, double rough, double stones) const {
    const int placements = recording.placements > 0 ? recording.placements : 120;
    const int executions = recording.executions_per_placement > 0 ? recording.executions_per_placement : 3;
    SampleSet s;
    s.commands = (Eigen::MatrixXd(2, 1) << 0.5, -0.5).finished();
    s.command_dim_names = {"long"};
    s.command_labels = {"fwd", "back"};
    const int n = placements * executions;
    s.command.resize(n), s.episode.resize(n), s.step.resize(n), s.x.resize(n, 2), s.z.resize(n, 2);
    std::normal_distribution<double> unit(0, 1);
    std::uniform_real_distribution<double> u(0, 1);
    for (int p = 0; p < placements; ++p) {
      std::mt19937_64 rng(recording.seed * 1000003 + p);
      const double heading = 2 * M_PI * u(rng);
      const int c = u(rng) < 0.5 ? 0 : 1;
      const Eigen::Vector2d g(unit(rng), unit(rng));
      const bool on_stone = u(rng) < 0.1;
      const double stone_dir = 2 * M_PI * u(rng);
      const Eigen::Vector2d tilt = tilt_sd * rough * g + (on_stone ? 0.04 * stones : 0.0) *
                                                          Eigen::Vector2d(std::cos(stone_dir), std::sin(stone_dir));
      const Eigen::Vector2d z0 = 0.17 * Eigen::Vector2d(std::cos(heading), std::sin(heading)) + tilt;
      for (int e = 0; e < executions; ++e) {
        const int i = p * executions + e;
        s.command(i) = c, s.episode(i) = p, s.step(i) = e;
        s.z.row(i) = (z0 + 0.002 * Eigen::Vector2d(unit(rng), unit(rng))).transpose();
        const double spread = 0.01 * (1 + 0.8 * (rough - 1));
        s.x.row(i) << s.commands(c, 0) * 0.1 + spread * unit(rng), 0.2 * s.z(i, 1) + spread * unit(rng);
      }
    }
    s.x_names = {"dx", "dy"}, s.x_units = {"m", "m"};
    s.z_names = {"pitch", "roll"}, s.z_units = {"rad", "rad"};
    s.source = "ground fake";
    s.metadata["protocol"] = recording.protocol;
    s.metadata["seed"] = std::to_string(recording.seed);
    return s;
  }
  std::vector<Knob> knobs_;
};

struct GroundPair {
  AnalysisInputs in;
  CandidateSet set;
};

// The sim set at `sim`'s nominal (seed 11) and a real set from `real` (seed 12) at `planted`.
GroundPair MakePair(const GroundFake& real, const std::vector<KnobValue>& planted,
                    const GroundFake& sim = GroundFake()) {
  Recording r;
  r.protocol = "paper", r.seed = 11, r.placements = 160;
  Recording rr = r;
  rr.seed = 12;
  GroundPair out;
  out.in = PrepareInputs(sim.Record(r, {}, 1), real.Record(rr, planted, 1), 1);
  out.set.recording = out.in.recording;
  out.set.recording.placements = 80;
  return out;
}

GroundSearchOptions Options() {
  GroundSearchOptions o;
  o.search.misfit_elsewhere = true;  // as on uneven ground (the analysis sets it there)
  o.resamples = 100;
  return o;
}

TEST(GroundSearch, ARougherRealGroundIsNamedWithItsValue) {
  const GroundFake fake;
  const GroundPair pair = MakePair(fake, {{kRough, 2.0}});
  const GroundSearch g = SearchGround(fake, pair.in, pair.set, CandidateOptions{}, Options());
  ASSERT_TRUE(g.ran) << g.why;
  EXPECT_TRUE(g.on_slope) << "z traces the slope's circle";
  EXPECT_TRUE(g.moved);
  EXPECT_GT(g.ratio, 1.3);
  ASSERT_TRUE(g.search.named) << g.why;
  EXPECT_EQ(g.search.knob_index, kRough);
  EXPECT_NEAR(g.search.value, 2.0, 0.25 * 2.0);
  EXPECT_EQ(g.search.by, "ground_search");
  ASSERT_EQ(g.curves.size(), 2u);
  for (const GroundCurve& c : g.curves) {
    EXPECT_TRUE(std::is_sorted(c.values.begin(), c.values.end()));
    if (c.knob_index == kStones && c.meets) EXPECT_FALSE(c.tilt_as_well) << "boulders tilt a few placements far";
  }
  Verdict v;
  v.status = "unexplained";
  v.sentence = "Unexplained mismatch.";
  AddGroundSearch(fake, g, &v);
  EXPECT_EQ(v.status, "partly_explained");
  ASSERT_EQ(v.named.size(), 1u);
  EXPECT_EQ(v.named[0].knob, "terrain.rough.rms_scale");
  EXPECT_NE(v.sentence.find("tilts more variously"), std::string::npos) << v.sentence;
}

// Terraces tilt the standing robot about the slope's circle more than the circle's fit accepts
// (a radius under 4 robust SDs of the radial residuals); a simulator that says its ground is sloped
// keeps the comparison on the circle, and a rougher real ground moves the spread there. Asked of the
// fit alone, the stage measures each tilt's distance from the median z, which the circle fills.
TEST(GroundSearch, ASlopedGroundComparesOnTheCircleWhereTheTiltsBlurIt) {
  GroundFake sim, real;
  sim.tilt_sd = real.tilt_sd = 0.06;
  sim.sloped = real.sloped = true;
  real.extra_roughness = 2;
  const GroundPair pair = MakePair(real, {}, sim);
  ASSERT_FALSE(FitSlopeGeometry(pair.in.sim_set, pair.in.pitch_col, pair.in.roll_col).valid);
  GroundSearchOptions o = Options();
  const GroundSearch g = SearchGround(sim, pair.in, pair.set, CandidateOptions{}, o);
  ASSERT_TRUE(g.ran) << g.why;
  EXPECT_TRUE(g.on_slope);
  EXPECT_TRUE(g.moved);
  EXPECT_GT(g.ratio, 1.5);
  GroundFake unsaid;
  unsaid.tilt_sd = 0.06;
  const GroundSearch h = SearchGround(unsaid, pair.in, pair.set, CandidateOptions{}, o);
  EXPECT_FALSE(h.on_slope);
  EXPECT_LT(h.ratio, g.ratio);
}

// With the null-corrected gain (LegSearchOptions::null_corrected_gain) the rougher ground keeps its
// name: its recording's model fits the real samples better than the nominal's, and the nominal's
// own recording at other places worse (a broader model there is no gain).
TEST(GroundSearch, TheNullCorrectedGainKeepsARightName) {
  const GroundFake fake;
  const GroundPair pair = MakePair(fake, {{kRough, 2.0}});
  GroundSearchOptions o = Options();
  o.search.null_corrected_gain = true;
  const GroundSearch g = SearchGround(fake, pair.in, pair.set, CandidateOptions{}, o);
  ASSERT_TRUE(g.search.named) << g.why;
  EXPECT_EQ(g.search.knob_index, kRough);
  EXPECT_GT(g.search.real_gain, 0);
  EXPECT_LT(g.search.null_gain, g.search.real_gain);
  EXPECT_GE(g.search.z_null_corrected, o.search.z);
  EXPECT_TRUE(g.search.null_corrected_gate);
  const GroundSearch off = SearchGround(fake, pair.in, pair.set, CandidateOptions{}, Options());
  EXPECT_FALSE(off.search.null_corrected_gate) << "computed, not gating";
  EXPECT_TRUE(std::isfinite(off.search.z_null_corrected));
}

TEST(GroundSearch, ANullMovesNothingAndRecordsNothing) {
  const GroundFake fake;
  const GroundPair pair = MakePair(fake, {});
  const GroundSearch g = SearchGround(fake, pair.in, pair.set, CandidateOptions{}, Options());
  ASSERT_TRUE(g.ran) << g.why;
  EXPECT_FALSE(g.moved) << "ratio " << g.ratio << ", z " << g.z_moved;
  EXPECT_EQ(g.recorded + g.from_cache, 0);
  Verdict v;
  v.status = "clean";
  AddGroundSearch(fake, g, &v);
  EXPECT_EQ(v.status, "clean");
  EXPECT_TRUE(v.doubts.empty());
}

TEST(GroundSearch, ASpreadNoGroundKnobReachesIsADoubtNotAName) {
  GroundFake real;
  real.extra_roughness = 8;  // beyond the roughness knob's range (3)
  const GroundPair pair = MakePair(real, {});
  const GroundFake fake;
  const GroundSearch g = SearchGround(fake, pair.in, pair.set, CandidateOptions{}, Options());
  ASSERT_TRUE(g.moved);
  EXPECT_FALSE(g.search.named);
  EXPECT_NE(g.why.find("no ground knob gives that spread"), std::string::npos) << g.why;
  Verdict v;
  v.status = "clean";
  AddGroundSearch(fake, g, &v);
  EXPECT_EQ(v.status, "unexplained") << "a located mismatch nothing names";
  ASSERT_EQ(v.doubts.size(), 1u);
  EXPECT_NE(v.doubts[0].find("no ground knob"), std::string::npos);
}

TEST(GroundSearch, DoesNotRunWithoutGroundKnobs) {
  const GroundFake real;
  const GroundPair pair = MakePair(real, {{kRough, 2.0}});
  const GroundSearch g = SearchGround(GroundFake(false), pair.in, pair.set, CandidateOptions{}, Options());
  EXPECT_FALSE(g.ran);
  EXPECT_EQ(g.why, "the simulator has no ground knobs");
}

TEST(GroundSearch, TheStandingSpreadReadsTheFirstExecutionsAboutTheMedian) {
  SampleSet s;
  s.commands = Eigen::MatrixXd::Zero(1, 1);
  s.command_labels = {"c"};
  s.command = Eigen::VectorXi::Zero(8), s.episode.resize(8), s.step.resize(8);
  s.x = Eigen::MatrixXd::Zero(8, 1), s.z.resize(8, 2);
  // Level ground (no circle): four placements of two executions; first executions at distances
  // 0, 1, 2, 3 from (1, 1) along pitch, second executions far off (they must not count).
  for (int p = 0; p < 4; ++p) {
    for (int e = 0; e < 2; ++e) {
      const int i = 2 * p + e;
      s.episode(i) = p, s.step(i) = e;
      s.z.row(i) << (e == 0 ? 1.0 + p : 100.0), 1.0;
    }
  }
  const StandingSpread level = MeasureStandingSpread(s, 0, 1, nullptr, 50, 1);
  EXPECT_EQ(level.placements, 4);
  // The median of (1, 2, 3, 4) is 2.5 (pitch), 1 (roll): distances 1.5, 0.5, 0.5, 1.5.
  EXPECT_NEAR(level.value, 1.0, 1e-12);
  EXPECT_GT(level.se, 0);
}

TEST(GroundSearch, TheTiltDensityPrefersTheReferenceOfTheSameShape) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0, 1);
  std::vector<double> real, same, tailed;
  for (int i = 0; i < 300; ++i) real.push_back(unit(rng));
  for (int i = 0; i < 300; ++i) same.push_back(unit(rng));
  for (int i = 0; i < 300; ++i) tailed.push_back(i % 10 == 0 ? 6 * unit(rng) : 0.5 * unit(rng));
  EXPECT_GT(TiltLogDensity(real, same).mean(), TiltLogDensity(real, tailed).mean() + 0.1);
  const std::vector<double> flat(10, 2.0);
  EXPECT_TRUE(TiltLogDensity(real, flat).isZero()) << "no shape to compare: no information";
}

}  // namespace
}  // namespace dgmm::sim2real::test
