// Streaming fit and score from a file equal the in-memory LearnMotionModel and ScoreSampleSet.
#include "io/streaming.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "io/sample_set_io.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// A set of well-behaved samples (three clusters per command), so fits are meaningful.
SampleSet ClusteredSet(int n, int dz, std::uint64_t seed) {
  SampleSet s =
      test::RandomSet({.n = n, .dx = 2, .dz = dz, .commands = 3, .command_dims = 1}, seed);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const double centre = 4.0 * (i % 3) + s.command[i];
    for (int j = 0; j < s.pose_dim(); ++j) s.x(i, j) = centre + normal(rng);
    for (int j = 0; j < dz; ++j) s.z(i, j) = 0.5 * centre + normal(rng);
  }
  return s;
}

TEST(Streaming, FitFromFileEqualsInMemoryFit) {
  const fs::path dir = test::TestDir();
  for (int dz : {0, 1}) {
    const SampleSet set = ClusteredSet(3000, dz, 21 + dz);
    WriteSampleSet(set, dir / "s.h5");
    for (bool with_terrain : {true, false}) {
      MotionModelOptions options;
      options.seed = 5;
      options.with_terrain = with_terrain;
      const MotionModel expected = LearnMotionModel(set, options);
      // keep_bytes: the samples kept from the first pass (default), none (read twice), or the
      // first chunks kept and then dropped when the rest do not fit (read twice).
      for (std::size_t keep_bytes : {kStreamKeepBytes, std::size_t{0}, std::size_t{40000}}) {
        for (int chunk_rows : {1, 999, 4096}) {
          SCOPED_TRACE(testing::Message() << "dz " << dz << " terrain " << with_terrain
                                          << " chunk " << chunk_rows << " keep " << keep_bytes);
          long long last_done = 0;
          const MotionModel streamed = LearnMotionModelFromFile(
              dir / "s.h5", options, chunk_rows,
              [&](long long done, long long total) {
                EXPECT_GT(done, last_done);
                EXPECT_EQ(total, set.size());
                last_done = done;
              },
              nullptr, keep_bytes);
          EXPECT_EQ(last_done, set.size());
          test::ExpectSameModel(expected, streamed);
        }
      }
    }
  }
}

TEST(Streaming, ScoreFromFileEqualsScoreSampleSet) {
  const fs::path dir = test::TestDir();
  const SampleSet set = ClusteredSet(2000, 1, 3);
  WriteSampleSet(set, dir / "s.h5");
  const MotionModel model = LearnMotionModel(set, MotionModelOptions{});
  const ScoreSummary expected = ScoreSampleSet(model, set);
  const FileScore score = ScoreSampleSetFile(model, dir / "s.h5", 300);
  EXPECT_EQ(score.summary.samples, expected.samples);
  // Summation order differs (per command per chunk): relative rounding only.
  EXPECT_NEAR(score.summary.total_log_likelihood, expected.total_log_likelihood,
              1e-9 * std::abs(expected.total_log_likelihood));
  long long samples = 0;
  double total = 0;
  for (const auto& [command, c] : score.by_command) {
    EXPECT_EQ(c.label, set.command_labels[command]);
    samples += c.samples;
    total += c.total_log_likelihood;
  }
  EXPECT_EQ(samples, set.size());
  EXPECT_NEAR(total, score.summary.total_log_likelihood, 1e-9 * std::abs(total));
}

TEST(Streaming, ErrorsNameTheFile) {
  const fs::path dir = test::TestDir();
  const SampleSet set = ClusteredSet(100, 0, 4);
  WriteSampleSet(set, dir / "s.h5");
  MotionModel model = LearnMotionModel(set, MotionModelOptions{});
  model.mixtures.erase(1);
  model.command_labels.erase(1);
  model.command_values.erase(1);
  try {
    ScoreSampleSetFile(model, dir / "s.h5");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir / "s.h5").string(), 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace dgmm
