// `dgmm import`: a CSV file with a header row -> an HDF5 sample set (io/csv_import.h).
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "util/output_guard.h"
#include "io/csv_import.h"
#include "io/csv_reader.h"
#include "io/sample_set_io.h"
#include "util/atomic_file.h"

namespace dgmm::app {
namespace {

struct ImportArgs {
  std::string input, output;
  CsvImportOptions csv;
  std::string delimiter = ",";
  std::vector<std::string> units;
  bool json = false;
};

void Run(const ImportArgs& args) {
  RefuseOutputThatIsAnInput(args.output, {args.input});
  CsvImportOptions csv = args.csv;
  csv.delimiter = ParseDelimiter(args.delimiter);
  csv.units = ParseUnits(args.units);
  { AtomicFile probe(args.output); }  // fail before reading when the output is unwritable
  CsvImportSummary summary;
  const SampleSet set = ImportCsv(args.input, csv, &summary);
  if (!Quiet()) {
    for (const std::string& line : summary.dropped_report) std::fprintf(stderr, "dgmm: %s\n", line.c_str());
  }
  WriteSampleSet(set, args.output);
  if (args.json) {
    nlohmann::json out = {{"input", args.input},
                          {"output", args.output},
                          {"samples", set.size()},
                          {"pose_dim", set.pose_dim()},
                          {"terrain_dim", set.terrain_dim()},
                          {"commands", set.num_commands()},
                          {"episodes", set.has_sequence()},
                          {"standardized", !set.transform.empty()},
                          {"dropped_rows", summary.dropped_rows}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::printf("imported %d samples (%d pose, %d terrain dimensions, %d command%s%s) from %s\n",
              set.size(), set.pose_dim(), set.terrain_dim(), set.num_commands(),
              set.num_commands() == 1 ? "" : "s", set.transform.empty() ? "" : ", standardised",
              args.input.c_str());
  std::printf("wrote %s\n", args.output.c_str());
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<ImportArgs>();
  CLI::App* cmd = root.add_subcommand(
      "import",
      "Import a CSV file (header row; columns chosen by name) as an HDF5 sample set. Without "
      "--command-cols every row belongs to one command; with them, each distinct tuple of "
      "values is one command, labelled by the values joined with commas; a command column holding "
      "text (e.g. 'fast') is taken as string labels. Lists are comma-separated.");
  cmd->add_option("input", args->input, "CSV file with a header row")->required();
  cmd->add_option("-o,--output", args->output, "sample set to write (.h5)")->required();
  cmd->add_option("--command-cols", args->csv.command_columns,
                  "columns holding the command (comma-separated; optional)")
      ->delimiter(',');
  cmd->add_option("--pose-cols", args->csv.pose_columns,
                  "columns of the pose change x (comma-separated)")
      ->delimiter(',')
      ->required();
  cmd->add_option("--terrain-cols", args->csv.terrain_columns,
                  "columns of the terrain z observed before the command (optional)")
      ->delimiter(',');
  cmd->add_option("--continuous-cols", args->csv.continuous_command_columns,
                  "continuous command columns (e.g. vx,wz): conditioning dimensions stored first "
                  "in z, so models give p(x | command, z) for any value (optional)")
      ->delimiter(',');
  cmd->add_option("--delimiter", args->delimiter, "field separator: , ; tab | space")
      ->capture_default_str();
  cmd->add_flag("--drop-invalid", args->csv.drop_invalid,
                "skip rows with empty, NaN, Inf or non-numeric cells (or the wrong number of "
                "fields) and report how many; default: refuse the file naming file, line and "
                "column");
  cmd->add_option("--units", args->units,
                  "units of pose/terrain columns converted to m and rad, COLUMN=UNIT "
                  "comma-separated (e.g. yaw=deg,dx=mm; units m cm mm rad deg)")
      ->delimiter(',');
  cmd->add_option("--episode-col", args->csv.episode_column,
                  "integer episode id; the step is the row's order within its episode");
  cmd->add_flag("--standardize", args->csv.standardize,
                "store x||z with mean 0 and sd 1 per dimension plus the transform back to raw "
                "units");
  cmd->add_option("--source", args->csv.source, "where the data came from (e.g. sim, real)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print the summary as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("import", Setup);
}  // namespace dgmm::app
