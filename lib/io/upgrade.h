#pragma once
// `dgmm upgrade`: a trusted version-1 file (variable-length strings, no metadata checksums)
// rewritten with the same content as version 2 (docs/file-format.md, "Format version 2").
#include <string>

namespace dgmm {

struct UpgradeSummary {
  std::string kind;          // "sample_set" or "model"
  long long from_version = 0;
  bool written = false;      // false: the file already was version 2, nothing written
  long long samples = 0;     // sample sets: rows copied
};

// Reads `input` (version 1 only with the legacy string reader; the caller vouches for it) and
// writes `output` atomically. Throws InputError for anything that is neither version.
UpgradeSummary UpgradeFile(const std::string& input, const std::string& output);

}  // namespace dgmm
