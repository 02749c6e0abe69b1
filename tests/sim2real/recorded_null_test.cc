// The recorded null: the nominal re-recorded with the real set's design stands where null pairs
// stand, on a fake whose placements share an offset the sim model's z does not explain (rough
// ground) and whose real set has another design than the sim set.
#include "sim2real/recorded_null.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim2real/selection.h"
#include "tests/sim2real/fake_simulator.h"

namespace dgmm::sim2real {
namespace {

test::FakeSimulator& RoughFake() {
  static test::FakeSimulator* fake = [] {
    auto* f = new test::FakeSimulator();
    f->ground_sd = 1.0;
    f->honour_executions = true;
    return f;
  }();
  return *fake;
}

const Recording kRealDesign{"paper", 0, 30, 3};  // seed set per real set

RecordedNullOptions Options(int draws) {
  RecordedNullOptions o;
  o.draws = draws;
  o.recording.cache_dir = "-";
  return o;
}

// A baseline of the sim set against `real`: the sim model and the real folds.
Baseline BaselineOf(const AnalysisInputs& in) {
  BaselineOptions o;
  o.locate.mmd.permutations = 50;
  return LocateMismatch(in, o);
}

TEST(RecordedNull, RepeatsTheRealSetsDesign) {
  const SampleSet sim = RoughFake().Record({"paper", 7, 0}, {}, 1);
  Recording design = kRealDesign;
  design.seed = 1007;
  const AnalysisInputs in = PrepareInputs(sim, RoughFake().Record(design, {}, 1), 1);
  const Recording r = RealDesign(in, 99);
  EXPECT_EQ(r.protocol, in.recording.protocol);
  EXPECT_EQ(r.seed, 99u);
  EXPECT_EQ(r.placements, 30);
  EXPECT_EQ(r.executions_per_placement, 3);
  SampleSet no_sequence = in.real_set;
  no_sequence.episode.resize(0), no_sequence.step.resize(0);
  const Recording each = RealDesign(PrepareInputs(sim, no_sequence, 1), 99);
  EXPECT_EQ(each.placements, 90) << "every sample its own placement";
  EXPECT_EQ(each.executions_per_placement, 1);
}

// A re-recording never repeats the sim set's or the real set's own places and noise (both seeds from
// their metadata); a real log whose metadata seed does not read as one is recorded at the seed asked.
TEST(RecordedNull, NeverTheSimSetsNorTheRealSetsOwnSeed) {
  const SampleSet sim = RoughFake().Record({"paper", 7, 0}, {}, 1);
  Recording design = kRealDesign;
  design.seed = 8;
  SampleSet real = RoughFake().Record(design, {}, 1);
  const AnalysisInputs in = PrepareInputs(sim, real, 1);
  ASSERT_EQ(in.recording.seed, 7u);
  ASSERT_EQ(in.real_seed, std::optional<std::uint64_t>(8));
  EXPECT_EQ(RealDesign(in, 7).seed, 9u) << "past the sim set's 7 and the real set's 8";
  EXPECT_EQ(RealDesign(in, 8).seed, 9u);
  EXPECT_EQ(RealDesign(in, 10).seed, 10u);
  real.metadata["seed"] = "log-2026-12-02";
  const AnalysisInputs log = PrepareInputs(sim, real, 1);
  EXPECT_FALSE(log.real_seed.has_value());
  EXPECT_EQ(RealDesign(log, 8).seed, 8u);
}

// Null pairs of one sim set (real sets of the sim's physics at other seeds, 30 placements of 3
// executions against the sim set's 72 of 5): their mean shortfall lies within 3 SE of the
// recorded null's mean, and each one within 3 of the null's SD of it.
TEST(RecordedNull, StandsWhereNullPairsStand) {
  const SampleSet sim = RoughFake().Record({"paper", 7, 0}, {}, 1);
  std::vector<double> pairs;
  NullShortfall null;
  for (std::uint64_t s = 0; s < 8; ++s) {
    Recording design = kRealDesign;
    design.seed = 2000 + s;
    const AnalysisInputs in = PrepareInputs(sim, RoughFake().Record(design, {}, 1), 1);
    const Baseline base = BaselineOf(in);
    pairs.push_back(base.ll_ceiling - base.ll_sim);
    if (s == 0) null = RecordNullShortfall(RoughFake(), in, base, Options(8));
  }
  double mean = 0, var = 0;
  for (double v : pairs) mean += v / pairs.size();
  for (double v : pairs) var += (v - mean) * (v - mean) / (pairs.size() - 1);
  ASSERT_TRUE(null.recorded);
  ASSERT_EQ(null.draws, 8);
  EXPECT_EQ(null.recordings, 8) << "no cache: every re-recording recorded";
  EXPECT_NEAR(null.mean_se, null.sd / std::sqrt(8.0), 1e-12);
  EXPECT_LT(std::abs(mean - null.mean), 3 * std::hypot(std::sqrt(var / pairs.size()), null.mean_se))
      << "null pairs " << mean << " (SD " << std::sqrt(var) << "), recorded null " << null.mean << " (SD "
      << null.sd << ")";
  EXPECT_GT(null.sd, 0);
  for (double v : pairs) EXPECT_LT(std::abs(v - null.mean), 3 * null.sd + 3 * null.mean_se) << v;
}

// The re-recordings are seeded from the options alone: the same null twice, another with another
// seed, and never the sim set's own recording.
TEST(RecordedNull, IsSeededAndNeverTheSimSetsOwnRecording) {
  const SampleSet sim = RoughFake().Record({"paper", 7, 0}, {}, 1);
  Recording design = kRealDesign;
  design.seed = 3000;
  const AnalysisInputs in = PrepareInputs(sim, RoughFake().Record(design, {}, 1), 1);
  const Baseline base = BaselineOf(in);
  const NullShortfall a = RecordNullShortfall(RoughFake(), in, base, Options(3));
  const NullShortfall b = RecordNullShortfall(RoughFake(), in, base, Options(3));
  RecordedNullOptions other = Options(3);
  other.seed = 2;
  const NullShortfall c = RecordNullShortfall(RoughFake(), in, base, other);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.sd, b.sd);
  EXPECT_NE(a.mean, c.mean);
  EXPECT_NE(RealDesign(in, in.recording.seed).seed, in.recording.seed) << "never the sim set's own places";
}

TEST(RecordedNull, RefusesFewerThanTwoDraws) {
  std::string error;
  EXPECT_FALSE(Options(1).IsValid(&error));
  EXPECT_NE(error.find("draws >= 2"), std::string::npos) << error;
}

}  // namespace
}  // namespace dgmm::sim2real
