#pragma once
// Sample sets as HDF5 files (schema: docs/file-format.md). Writes are atomic (temp + rename).
#include <string>

#include "core/sample_set.h"

namespace dgmm {

// Writes the set (validated first) to `path`. Throws InputError naming the path on failure;
// leaves no file behind then.
void WriteSampleSet(const SampleSet& set, const std::string& path);
// Reads a whole set. Throws InputError "<path>: <field>: <problem>" for a missing, truncated,
// foreign or inconsistent file.
SampleSet ReadSampleSet(const std::string& path);
// "sample_set", "model" or throws InputError for anything else (foreign HDF5, not HDF5).
std::string DgmmFileKind(const std::string& path);

}  // namespace dgmm
