// Chunked reading and writing give the same samples as whole-set reads and writes.
#include "io/sample_stream.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "io/sample_set_io.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// All chunks of the reader concatenated; checks every chunk's size and tables on the way.
SampleSet ReadInChunks(const std::string& path, int chunk_rows) {
  SampleSetReader reader(path, chunk_rows);
  SampleSet chunk;
  std::vector<SampleSet> chunks;
  long long total = 0;
  while (reader.Next(&chunk)) {
    const long long expected = std::min<long long>(chunk_rows, reader.size() - total);
    EXPECT_EQ(chunk.size(), expected);
    EXPECT_EQ(chunk.command_labels, reader.header().command_labels);
    EXPECT_EQ(chunk.Validate(), "");
    total += chunk.size();
    chunks.push_back(chunk);
  }
  EXPECT_EQ(total, reader.size());
  SampleSet all = reader.header();
  const int n = static_cast<int>(total);
  all.command.resize(n);
  all.x.resize(n, all.pose_dim());
  all.z.resize(all.terrain_dim() > 0 ? n : 0, all.terrain_dim());
  if (!chunks.empty() && chunks[0].has_sequence()) {
    all.episode.resize(n);
    all.step.resize(n);
  }
  int row = 0;
  for (const SampleSet& c : chunks) {
    all.command.segment(row, c.size()) = c.command;
    all.x.middleRows(row, c.size()) = c.x;
    if (all.terrain_dim() > 0) all.z.middleRows(row, c.size()) = c.z;
    if (c.has_sequence()) {
      all.episode.segment(row, c.size()) = c.episode;
      all.step.segment(row, c.size()) = c.step;
    }
    row += c.size();
  }
  return all;
}

TEST(SampleSetReader, ChunksConcatenateToTheWholeSet) {
  const fs::path dir = test::TestDir();
  const SampleSet set = test::RandomSet({.n = 20000,
                                         .dx = 3,
                                         .dz = 2,
                                         .commands = 5,
                                         .command_dims = 2,
                                         .episodes = true,
                                         .transform = true},
                                        11);
  WriteSampleSet(set, dir / "s.h5");
  const SampleSet whole = ReadSampleSet(dir / "s.h5");
  test::ExpectSameSet(set, whole);
  // Chunk sizes that do and do not divide N or the file's 16384-row HDF5 chunks.
  for (int chunk_rows : {1000, 7, 16384, 16385, 65536}) {
    SCOPED_TRACE(chunk_rows);
    test::ExpectSameSet(whole, ReadInChunks(dir / "s.h5", chunk_rows));
  }
}

TEST(SampleSetReader, HeaderHasTablesButNoSamples) {
  const fs::path dir = test::TestDir();
  const SampleSet set = test::RandomSet({.n = 30, .dx = 2, .dz = 1, .commands = 2}, 5);
  WriteSampleSet(set, dir / "s.h5");
  SampleSetReader reader(dir / "s.h5");
  EXPECT_EQ(reader.size(), 30);
  EXPECT_EQ(reader.header().size(), 0);
  EXPECT_EQ(reader.header().pose_dim(), 2);
  EXPECT_EQ(reader.header().terrain_dim(), 1);
  EXPECT_EQ(reader.header().command_labels, set.command_labels);
  EXPECT_EQ(reader.header().z_names, set.z_names);
}

TEST(SampleSetWriter, AppendedChunksEqualOneWrite) {
  const fs::path dir = test::TestDir();
  const SampleSet set =
      test::RandomSet({.n = 1001, .dx = 2, .dz = 1, .commands = 3, .episodes = true}, 9);
  SampleSetWriter writer((dir / "chunked.h5").string(), set);
  for (int start = 0; start < set.size(); start += 100) {
    std::vector<int> rows;
    for (int i = start; i < std::min(set.size(), start + 100); ++i) rows.push_back(i);
    writer.Append(set.Subset(rows));
  }
  EXPECT_FALSE(fs::exists(dir / "chunked.h5"));  // only on Commit
  writer.Commit();
  test::ExpectSameSet(set, ReadSampleSet(dir / "chunked.h5"));
  EXPECT_EQ(test::CountTempFiles(dir), 0);
}

TEST(SampleSetWriter, AbandonedOrRejectedWritesLeaveNothing) {
  const fs::path dir = test::TestDir();
  const SampleSet set = test::RandomSet({.n = 10, .dx = 2, .commands = 2}, 3);
  {
    SampleSetWriter writer((dir / "a.h5").string(), set);
    writer.Append(set);
  }  // destroyed without Commit
  EXPECT_FALSE(fs::exists(dir / "a.h5"));
  SampleSet bad = set;
  bad.command[4] = 2;  // out of the command table
  {
    SampleSetWriter writer((dir / "b.h5").string(), set);
    EXPECT_THROW(writer.Append(bad), InputError);
    SampleSet wrong_dims = test::RandomSet({.n = 10, .dx = 3, .commands = 2}, 3);
    EXPECT_THROW(writer.Append(wrong_dims), InputError);
    EXPECT_THROW(SampleSetWriter((dir / "c.h5").string(), set).Commit(), InputError);  // empty
  }
  EXPECT_FALSE(fs::exists(dir / "b.h5"));
  EXPECT_FALSE(fs::exists(dir / "c.h5"));
  EXPECT_EQ(test::CountTempFiles(dir), 0);
}

}  // namespace
}  // namespace dgmm
