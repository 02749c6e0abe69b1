// `dgmm import-log`: time-stamped CSV streams (commands, pose, attitude) -> an HDF5 sample set
// (io/log_import.h, docs/log-import.md).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "io/csv_reader.h"
#include "io/log_import.h"
#include "io/sample_set_io.h"
#include "util/atomic_file.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct ImportLogArgs {
  LogImportOptions log;
  std::string output, delimiter = ",", time_column;
  std::vector<std::string> units;
  std::string bin_rule = "quantile";
  double rate_hz = 0;
  bool no_header = false;
  bool json = false, quiet = false;
};

// The options the flags name (delimiter, units, header, rates, bin rule, time column).
LogImportOptions OptionsFromArgs(const ImportLogArgs& args) {
  LogImportOptions o = args.log;
  o.delimiter = ParseDelimiter(args.delimiter);
  o.units = ParseUnits(args.units);
  o.has_header = !args.no_header;
  if (args.rate_hz < 0 || !std::isfinite(args.rate_hz)) {
    throw MakeInputError("", "--rate", "expected rows per second > 0");
  }
  if (args.rate_hz > 0 && !args.time_column.empty()) {
    throw MakeInputError("", "--rate/--time-col", "give one: times come from a column or a rate");
  }
  if (args.rate_hz > 0) {
    for (LogStream* s : {&o.commands, &o.pose, &o.attitude}) s->rate_hz = args.rate_hz;
  }
  if (args.bin_rule == "width") {
    o.bins.rule = CommandBinOptions::Rule::kWidth;
  } else if (args.bin_rule != "quantile") {
    throw MakeInputError("", "--bin-rule", "'" + args.bin_rule + "', expected quantile or width");
  }
  if (!args.time_column.empty()) {
    for (LogStream* s : {&o.commands, &o.pose, &o.attitude}) {
      if (s->time_column == "t") s->time_column = args.time_column;
    }
  }
  return o;
}

// Warnings, dropped rows and commands without a sample, on stderr unless quiet.
void ReportProblems(const LogImportSummary& summary, const std::string& commands_path) {
  if (Quiet()) return;
  for (const auto& w : summary.warnings) std::fprintf(stderr, "dgmm: warning: %s\n", w.c_str());
  for (const auto& line : summary.dropped_report) std::fprintf(stderr, "dgmm: %s\n", line.c_str());
  if (summary.unmatched_commands.empty()) return;
  std::string list;
  for (const auto& c : summary.unmatched_commands) list += (list.empty() ? "" : "; ") + c;
  std::fprintf(stderr,
               "dgmm: warning: %zu command(s) in %s gave no sample (segments too short or "
               "outside the pose/attitude coverage): %s\n",
               summary.unmatched_commands.size(), commands_path.c_str(), list.c_str());
}

nlohmann::json ContinuousJson(const LogImportSummary& summary) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : summary.continuous) {
    out.push_back({{"column", c.name},
                   {"min", c.min},
                   {"max", c.max},
                   {"spread_of_window_averages", c.spread},
                   {"median_variation_inside_window", c.median_within}});
  }
  return out;
}

nlohmann::json ImportJson(const SampleSet& set, const LogImportSummary& summary,
                          const std::string& output) {
  return {{"output", output},
          {"samples", set.size()},
          {"pose_dim", set.pose_dim()},
          {"terrain_dim", set.terrain_dim()},
          {"commands", set.command_labels},
          {"episodes", summary.episodes},
          {"trials", summary.trials},
          {"segments", summary.segments},
          {"windows_kept", summary.samples},
          {"dropped",
           {{"short_segments", summary.short_segments},
            {"segment_remainders", summary.remainders},
            {"command_rows_outside_coverage", summary.commands_outside_coverage},
            {"trials_without_overlap", summary.trials_without_overlap},
            {"invalid_rows", summary.dropped_rows}}},
          {"near_miss_remainders", summary.near_miss_remainders},
          {"largest_near_miss_s", summary.largest_near_miss_s},
          {"window_s",
           {{"min", summary.min_window_s},
            {"median", summary.median_window_s},
            {"max", summary.max_window_s}}},
          {"gap_s", summary.gap_s},
          {"min_duration_s", summary.min_duration_s},
          {"time_tolerance_s", summary.time_tolerance_s},
          {"warnings", summary.warnings},
          {"continuous_commands", ContinuousJson(summary)},
          {"unmatched_commands", summary.unmatched_commands}};
}

void Run(const ImportLogArgs& args) {
  const LogImportOptions o = OptionsFromArgs(args);
  RefuseOutputThatIsAnInput(args.output, {o.commands.path, o.pose.path, o.attitude.path});
  { AtomicFile probe(args.output); }  // fail before reading when the output is unwritable
  LogImportSummary summary;
  const SampleSet set = ImportLog(o, &summary);
  WriteSampleSet(set, args.output);
  ReportProblems(summary, o.commands.path);
  if (args.json) {
    std::cout << ImportJson(set, summary, args.output).dump(2) << "\n";
    return;
  }
  std::printf("imported %s\n", summary.BriefReport().c_str());
  std::printf("%s\n", summary.WindowReport().c_str());
  if (const std::string c = summary.ContinuousReport(); !c.empty()) std::printf("%s\n", c.c_str());
  std::printf("%s:", Plural(set.num_commands(), "command").c_str());
  for (const auto& label : set.command_labels) std::printf(" [%s]", label.c_str());
  std::printf("\nwrote %s\n", args.output.c_str());
}

// The streams: files (or folders or globs), columns, times and units.
void AddStreamFlags(CLI::App* cmd, ImportLogArgs* args) {
  LogImportOptions& o = args->log;
  cmd->add_option("--commands", o.commands.path,
                  "command stream: a CSV file, or a folder of them or a glob pattern (quoted) with "
                  "one file per trial")
      ->required();
  cmd->add_option("--command-cols", o.commands.columns,
                  "command columns (comma-separated; numbers, or text taken as labels)")
      ->delimiter(',');
  cmd->add_option("--continuous-cols", o.continuous_columns,
                  "continuous command columns of the command stream (e.g. vx,vy,wz): not cut "
                  "into commands; each window keeps their time average as leading conditioning "
                  "dimensions of z, so models give p(x | command, z) for any value (needs "
                  "--window)")
      ->delimiter(',');
  cmd->add_option("--pose", o.pose.path,
                  "pose stream in a fixed frame (e.g. map/odom): a CSV file, folder or glob; "
                  "trial files are paired with the command files by the part of their names "
                  "that differs")
      ->required();
  cmd->add_option("--pose-cols", o.pose.columns,
                  "x,y,yaw (planar) or x,y,z,roll,pitch,yaw (6-DoF) columns, in that order")
      ->delimiter(',')
      ->required();
  cmd->add_option("--attitude", o.attitude.path,
                  "attitude (IMU) stream: a CSV file, folder or glob (optional)");
  cmd->add_option("--terrain-cols", o.attitude.columns,
                  "attitude angle columns stored as the terrain z (e.g. pitch,roll)")
      ->delimiter(',');
  cmd->add_option("--time-col", args->time_column, "time column name of every stream (default t)");
  auto* rate = cmd->add_option("--rate", args->rate_hz,
                               "rows per second of every stream without a time column (row i at "
                               "t = i / rate from the file's start)");
  cmd->add_option("--commands-rate", o.commands.rate_hz, "rows per second of the command stream")
      ->excludes(rate);
  cmd->add_option("--pose-rate", o.pose.rate_hz, "rows per second of the pose stream")
      ->excludes(rate);
  cmd->add_option("--attitude-rate", o.attitude.rate_hz, "rows per second of the attitude stream")
      ->excludes(rate);
  cmd->add_flag("--no-header", args->no_header,
                "the files have no header row: name columns by position, 1, 2, ... (e.g. "
                "--pose-cols 1,2,3)");
  cmd->add_option("--commands-time", o.commands.time_column, "time column of the command stream");
  cmd->add_option("--pose-time", o.pose.time_column, "time column of the pose stream");
  cmd->add_option("--attitude-time", o.attitude.time_column, "time column of the attitude stream");
  cmd->add_option("--units", args->units,
                  "units converted to s, m and rad, COLUMN=UNIT comma-separated (e.g. "
                  "t_ms=ms,x=mm,yaw=deg; units s ms us ns m cm mm rad deg); default SI")
      ->delimiter(',');
}

// How samples are cut: episodes, windows, tolerance, bins, durations, invalid rows, output.
void AddSampleFlags(CLI::App* cmd, ImportLogArgs* args) {
  LogImportOptions& o = args->log;
  cmd->add_option("--episode-col", o.episode_column,
                  "integer episode column of the command stream (default: one episode per trial "
                  "file; a single file is split into episodes at logging gaps)");
  cmd->add_option("--gap", o.gap_s,
                  "a pause longer than this (s) in the pose or attitude stream ends an episode "
                  "(0: 10 x the slower stream's median interval)")
      ->capture_default_str();
  cmd->add_option("--window", o.window_s,
                  "cut each command segment into windows of this many seconds (0: one sample "
                  "per command segment)")
      ->capture_default_str();
  cmd->add_option("--min-duration", o.min_duration_s,
                  "skip command segments shorter than this (s; 0: two pose intervals)")
      ->capture_default_str();
  cmd->add_option("--bins", o.bins.bins,
                  "bin numeric command columns into this many bins of equal counts (quantiles; "
                  "--bin-rule width: equal widths); a zero is its own command (a stop); 0: every "
                  "distinct value is a command")
      ->capture_default_str();
  cmd->add_option("--bin-rule", args->bin_rule, "quantile or width (for --bins)")
      ->capture_default_str();
  cmd->add_option("--bin-edges", o.bins.edges,
                  "explicit inner bin edges of numeric command columns, increasing, "
                  "comma-separated (instead of --bins); a zero is its own command")
      ->delimiter(',');
  cmd->add_option("--time-tolerance", o.time_tolerance_s,
                  "each end of a window may lie this long (s) beyond its segment's data, so a "
                  "window one pose sample short is kept (0: half the median pose interval)")
      ->capture_default_str();
  cmd->add_flag("--per-second", o.per_second,
                "divide each pose change by its window's duration (rates in m/s and rad/s), for "
                "samples of unequal duration");
  cmd->add_option("--delimiter", args->delimiter, "field separator: , ; tab | space")
      ->capture_default_str();
  cmd->add_flag("--drop-invalid", o.drop_invalid,
                "skip rows with empty, NaN or non-numeric cells, ragged rows or times that do "
                "not increase, and report how many per file; default: refuse naming file, "
                "line and column");
  cmd->add_option("--source", o.source, "where the data came from")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "sample set to write (.h5)")->required();
  cmd->add_flag("--json", args->json, "print the summary as JSON");
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<ImportLogArgs>();
  CLI::App* cmd = root.add_subcommand(
      "import-log",
      "Turn time-stamped CSV logs (a command stream, a pose stream and optionally an IMU "
      "attitude stream, each with its own time column or rate, each one file or a folder or "
      "glob of per-trial files) into an HDF5 sample set: "
      "streams are joined by time (commands held, pose and attitude interpolated), episodes "
      "split at logging gaps, samples cut at command changes (or into --window seconds) and the "
      "pose change expressed in the robot frame at the sample start (docs/log-import.md). "
      "Lists are comma-separated.");
  AddStreamFlags(cmd, args.get());
  AddSampleFlags(cmd, args.get());
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("import-log", Setup);
}  // namespace dgmm::app
