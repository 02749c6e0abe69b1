#pragma once
// Chunked reading and writing of a sample set file: memory stays bounded by the chunk size,
// whatever the file size.
#include <memory>
#include <string>

#include "core/sample_set.h"

namespace dgmm {

class SampleSetReader {
 public:
  // Opens the file and reads its tables (commands, names, transform) but no samples.
  explicit SampleSetReader(const std::string& path, int chunk_rows = 65536);
  ~SampleSetReader();
  // Everything but the per-sample arrays (those are empty).
  const SampleSet& header() const;
  long long size() const;
  // Next chunk of samples (per-sample fields filled, tables shared with header()); false at end.
  bool Next(SampleSet* chunk);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes a sample set chunk by chunk: the tables of `header` (its per-sample arrays are
// ignored), then every Append()ed chunk in order. The file appears at `path` only on Commit();
// destroying the writer before that leaves nothing behind. Throws InputError naming the path.
class SampleSetWriter {
 public:
  SampleSetWriter(const std::string& path, const SampleSet& header);
  ~SampleSetWriter();
  // Appends the samples of `chunk` (same dimensions as the header; command indices in range,
  // finite values; episode/step present iff the first chunk had them).
  void Append(const SampleSet& chunk);
  long long size() const;
  // Closes the file and renames it onto `path`. An empty set is an InputError.
  void Commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dgmm
