// Recordings through the simulator interface: the cache returns what was recorded, its key
// follows the fingerprint, recording and values, and the batch does not depend on the threads.
#include "sim2real/simulation_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <unistd.h>

#include "tests/sim2real/fake_simulator.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

TEST(SimulationCache, SecondRequestIsReadBackIdentical) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgmm_recording_cache_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const test::FakeSimulator fake;
  RecordingOptions options;
  options.cache_dir = dir.string();
  const Recording recording{"paper", 7, 6};
  const std::vector<std::vector<KnobValue>> requests = {{}, {{test::kFriction, 0.6}}};
  const RecordingBatch first = RecordBatch(fake, recording, requests, options);
  EXPECT_EQ(first.recorded, 2);
  const RecordingBatch second = RecordBatch(fake, recording, requests, options);
  EXPECT_EQ(second.from_cache, 2);
  EXPECT_EQ(second.recorded, 0);
  EXPECT_EQ(fake.records(), 2);
  for (int r = 0; r < 2; ++r) EXPECT_EQ(first.sets[r].x, second.sets[r].x);
  EXPECT_NE(first.sets[0].x, first.sets[1].x);
  std::filesystem::remove_all(dir);
}

TEST(SimulationCache, KeyFollowsValuesAndRecording) {
  const test::FakeSimulator fake;
  const Recording recording{"paper", 7, 6};
  EXPECT_NE(RecordingKey(fake, recording, {{test::kFriction, 0.6}}), RecordingKey(fake, recording, {{test::kFriction, 0.7}}));
  EXPECT_NE(RecordingKey(fake, recording, {}), RecordingKey(fake, Recording{"paper", 8, 6}, {}));
  EXPECT_NE(RecordingKey(fake, recording, {}), RecordingKey(fake, Recording{"paper", 7, 7}, {}));
  EXPECT_NE(RecordingKey(fake, recording, {}), RecordingKey(fake, Recording{"paper", 7, 6, 2}, {}));
  EXPECT_EQ(RecordingKey(fake, recording, {{test::kFriction, 0.6}}), RecordingKey(fake, recording, {{test::kFriction, 0.6}}));
}

TEST(SimulationCache, BatchDoesNotDependOnTheThreadCount) {
  const test::FakeSimulator fake;
  std::vector<std::vector<KnobValue>> requests;
  for (int k = 0; k < test::kNumFakeKnobs; ++k) requests.push_back({{k, fake.knobs()[k].probes[0]}});
  RecordingOptions one, four;
  one.cache_dir = four.cache_dir = "-";
  four.threads = 4;
  const RecordingBatch a = RecordBatch(fake, {"paper", 3, 0}, requests, one);
  const RecordingBatch b = RecordBatch(fake, {"paper", 3, 0}, requests, four);
  for (size_t r = 0; r < requests.size(); ++r) EXPECT_EQ(a.sets[r].x, b.sets[r].x) << r;
}

TEST(SimulationCache, TheLastRecordingsShareTheThreads) {
  const test::FakeSimulator fake;
  std::vector<std::vector<KnobValue>> requests(5);
  RecordingOptions options;
  options.cache_dir = "-";
  options.threads = 2;
  RecordBatch(fake, {"paper", 3, 6}, requests, options);
  std::vector<int> seen = fake.threads_seen();
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(seen, (std::vector<int>{1, 1, 1, 1, 2}));  // two rounds of one each, then one on both
}

TEST(SimulationCache, AFailedRecordingIsAnInputError) {
  const test::FakeSimulator fake;
  RecordingOptions options;
  options.cache_dir = "-";
  EXPECT_THROW(RecordBatch(fake, {"no-such-protocol", 1, 0}, {{}}, options), InputError);
}

}  // namespace
}  // namespace dgmm::sim2real
