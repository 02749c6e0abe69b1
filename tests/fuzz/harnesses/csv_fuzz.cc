// libFuzzer harness: the CSV importer (lib/io/csv_import.h). The first byte picks the options
// (commands, terrain, episodes, standardisation); the rest is the file. InputError is the
// expected outcome for bad input; anything else (crash, other exception, hang) is a finding.
#include "io/csv_import.h"

#include "fuzz_util.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t flags = data[0];
  dgmm::CsvImportOptions options;
  options.pose_columns = {"x", "y"};
  if (flags & 1) options.command_columns = {"c"};
  if (flags & 2) options.terrain_columns = {"z"};
  if (flags & 4) options.episode_column = "e";
  options.standardize = flags & 8;
  const std::string path = dgmm::fuzz::WriteInput(data + 1, size - 1, ".csv");
  try {
    dgmm::ImportCsv(path, options);
  } catch (const dgmm::InputError&) {
  }
  return 0;
}
