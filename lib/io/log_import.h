#pragma once
// Time-stamped robot logs -> a sample set. Several CSV streams (commands, pose, attitude), each
// with its own time column and units, are joined by time: the command is held from one command
// row to the next (zero-order hold), the pose and attitude are interpolated (linear for positions,
// shortest arc for angles). A stream may be one file or one file per trial (a folder or a glob,
// io/log_files.h); each trial is joined on its own. Episodes come from trials, logging gaps or an
// episode column, samples from cutting each episode at command changes and optionally into fixed
// windows. See docs/log-import.md.
#include <map>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "io/command_bins.h"

namespace dgmm {

// One CSV stream: its file (or folder or glob pattern), its time column and the value columns.
struct LogStream {
  std::string path;
  std::string time_column = "t";
  std::vector<std::string> columns;
  // > 0: the stream has no time column; data row i (from 0) is at t = i / rate_hz in each file.
  double rate_hz = 0;
};

struct LogImportOptions {
  // Commands: columns are the command (numbers, or text taken as labels); held until the next row.
  LogStream commands;
  // Pose in a fixed frame: columns x, y, yaw (planar) or x, y, z, roll, pitch, yaw (6-DoF,
  // R = Rz(yaw) Ry(pitch) Rx(roll)), in that order whatever their names.
  LogStream pose;
  // Optional attitude (IMU): columns are the terrain angles (e.g. pitch, roll) read at the start
  // of each sample. Empty path: no terrain.
  LogStream attitude;
  // In the commands stream; empty: one episode per trial file, split further at logging gaps
  // (a single file: episodes from gaps only).
  std::string episode_column;
  // A pause longer than gap_s between consecutive pose or attitude rows ends an episode;
  // 0: 10 x the slower of the two streams' median sampling interval.
  double gap_s = 0;
  double window_s = 0;        // > 0: cut each command segment into windows of this length
  double min_duration_s = 0;  // shorter segments are skipped; 0: 2 pose sampling intervals
  // Each end of a window may lie this long beyond the data of its segment (the pose held at the
  // last row): a window whose pose rows end one sample short of it is kept (and its duration
  // says so). 0: half the median pose interval.
  double time_tolerance_s = 0;
  // Numeric command columns binned into a few commands (io/command_bins.h; a zero is its own
  // command). bins.bins == 0 and no edges: every distinct value is a command.
  CommandBinOptions bins;
  // Continuous command columns of the command stream (e.g. vx, vy, yaw rate sent at 10-50 Hz):
  // not cut into commands; each sample keeps their time average over its window (zero-order
  // hold) as leading conditioning dimensions of z, before the attitude, so that models give
  // p(x | command, z) for any command value (docs/log-import.md). Needs window_s > 0.
  std::vector<std::string> continuous_columns;
  // Divide each pose change by its window's duration (rates, m/s and rad/s): for samples of
  // unequal duration (e.g. one sample per command segment).
  bool per_second = false;
  char delimiter = ',';
  bool has_header = true;  // false: no header row; columns are named by position "1", "2", ...
  bool drop_invalid = false;               // skip (and count) invalid rows instead of refusing
  std::map<std::string, double> units;     // column -> factor to SI (csv_reader.h ParseUnits)
  std::string source = "real";

  // False with one line naming the option when inconsistent (e.g. 4 pose columns).
  bool IsValid(std::string* error) const;
};

struct LogImportSummary {
  int trials = 0;  // file sets (1 when every stream is one file)
  long long command_rows = 0, pose_rows = 0, attitude_rows = 0;
  long long dropped_rows = 0;
  std::vector<std::string> dropped_report;  // one line per file
  // The values used (automatic choices; min_duration_s >= the window).
  double gap_s = 0, min_duration_s = 0, time_tolerance_s = 0;
  int episodes = 0;
  int segments = 0;        // command segments inside episodes
  int short_segments = 0;  // skipped: shorter than min_duration_s (or than one window)
  int samples = 0;         // windows kept
  // Time not turned into samples, by reason: segment remainders shorter than a window (and how
  // many of them fell short by at most two pose intervals, with the largest such shortfall, the
  // --time-tolerance that would keep them), and command rows outside the pose/attitude coverage.
  int remainders = 0, near_miss_remainders = 0;
  double largest_near_miss_s = 0;
  long long commands_outside_coverage = 0;
  int trials_without_overlap = 0;  // trials whose streams do not overlap in time
  // Durations of the samples (s): they differ when samples are whole command segments.
  double min_window_s = 0, median_window_s = 0, max_window_s = 0;
  std::vector<std::string> unmatched_commands;  // in the command stream but in no sample
  std::vector<std::string> warnings;  // e.g. continuous commands without --bins, unequal durations
  // Per continuous command column: the spread (standard deviation) of the window averages, and
  // the median over windows of the variation inside a window (time-weighted standard deviation).
  struct ContinuousColumn {
    std::string name;
    double min = 0, max = 0, spread = 0, median_within = 0;
  };
  std::vector<ContinuousColumn> continuous;
  std::string BriefReport() const;
  // "windows: 187 kept; dropped: ..." by reason, one line.
  std::string WindowReport() const;
  // One line per continuous command column: range, spread of the window averages and the
  // variation inside windows; empty without continuous columns.
  std::string ContinuousReport() const;
};

// Throws InputError naming file, line and column for bad input (unless drop_invalid for bad
// rows), or naming the option for options that do not fit the data (e.g. no overlap in time).
SampleSet ImportLog(const LogImportOptions& options, LogImportSummary* summary = nullptr);

}  // namespace dgmm
