#pragma once
// Chunked reading of a sample set file: memory stays bounded by the chunk size, whatever the
// file size.
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

}  // namespace dgmm
