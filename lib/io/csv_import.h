#pragma once
// CSV import: columns chosen by name; a file without a command column is one command.
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm {

struct CsvImportOptions {
  std::vector<std::string> command_columns;  // empty: a single command
  std::vector<std::string> pose_columns;     // required, >= 1
  std::vector<std::string> terrain_columns;  // optional
  std::string episode_column;                // optional; step = order within the episode
  bool standardize = false;                  // store x||z standardised plus the transform
  std::string source = "csv";
};

// Throws InputError "<path>: line L: <problem>" / "<path>: column 'c': not found (have: ...)"
// for empty files, ragged rows, unknown columns, non-numeric, NaN or Inf values.
SampleSet ImportCsv(const std::string& path, const CsvImportOptions& options);

}  // namespace dgmm
