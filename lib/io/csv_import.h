#pragma once
// CSV import: columns chosen by name; a file without a command column is one command.
#include <map>
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm {

struct CsvImportOptions {
  std::vector<std::string> command_columns;  // empty: a single command
  std::vector<std::string> pose_columns;     // required, >= 1
  std::vector<std::string> terrain_columns;  // optional
  // Continuous command columns (e.g. vx, yaw rate): conditioning dimensions like the terrain,
  // stored first in z (before terrain_columns) and counted in the set's metadata
  // "continuous_command_columns", so models give p(x | command, z) for any value.
  std::vector<std::string> continuous_command_columns;
  std::string episode_column;                // optional; step = order within the episode
  bool standardize = false;                  // store x||z standardised plus the transform
  std::string source = "csv";
  char delimiter = ',';
  // Rows with empty, NaN, Inf or non-numeric cells (or ragged rows): false refuses the file
  // naming file, line and column; true skips them and counts them in the summary.
  bool drop_invalid = false;
  // Column -> factor to SI (io/csv_reader.h ParseUnits), applied to pose and terrain columns.
  std::map<std::string, double> units;
};

struct CsvImportSummary {
  long long dropped_rows = 0;
  std::vector<std::string> dropped_report;  // one line per file (InvalidRows::Report)
};

// A command column whose non-empty cells are not all numbers is a label column: its distinct
// strings are the commands (numbered 0, 1, ... in order of appearance in the command table).
// Throws InputError "<path>: line L: <problem>" / "<path>: column 'c': not found (have: ...)"
// for empty files, ragged rows, unknown columns, non-numeric, NaN or Inf values (unless
// drop_invalid).
SampleSet ImportCsv(const std::string& path, const CsvImportOptions& options,
                    CsvImportSummary* summary = nullptr);

}  // namespace dgmm
