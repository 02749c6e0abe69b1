#pragma once
// Time-stamped robot logs -> a sample set. Several CSV streams (commands, pose, attitude), each
// with its own time column and units, are joined by time: the command is held from one command
// row to the next (zero-order hold), the pose and attitude are interpolated (linear for positions,
// shortest arc for angles). Episodes come from logging gaps (or an episode column), samples from
// cutting each episode at command changes and optionally into fixed windows. See docs/log-import.md.
#include <map>
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm {

// One CSV stream: its file, its time column and the value columns taken from it.
struct LogStream {
  std::string path;
  std::string time_column = "t";
  std::vector<std::string> columns;
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
  std::string episode_column;  // in the commands stream; empty: episodes from gaps only
  // A pause longer than gap_s between consecutive pose or attitude rows ends an episode;
  // 0: 10 x the slower of the two streams' median sampling interval.
  double gap_s = 0;
  double window_s = 0;        // > 0: cut each command segment into windows of this length
  double min_duration_s = 0;  // shorter segments are skipped; 0: 2 pose sampling intervals
  int bins = 0;               // > 0: numeric command columns binned into this many equal bins
  char delimiter = ',';
  bool drop_invalid = false;               // skip (and count) invalid rows instead of refusing
  std::map<std::string, double> units;     // column -> factor to SI (csv_reader.h ParseUnits)
  std::string source = "real";

  // False with one line naming the option when inconsistent (e.g. 4 pose columns).
  bool IsValid(std::string* error) const;
};

struct LogImportSummary {
  long long command_rows = 0, pose_rows = 0, attitude_rows = 0;
  long long dropped_rows = 0;
  std::vector<std::string> dropped_report;  // one line per file
  double gap_s = 0, min_duration_s = 0;  // the values used (automatic choices; >= the window)
  int episodes = 0;
  int segments = 0;        // command segments inside episodes
  int short_segments = 0;  // skipped: shorter than min_duration_s (or than one window)
  int samples = 0;
  std::vector<std::string> unmatched_commands;  // in the command stream but in no sample
  std::vector<std::string> warnings;            // e.g. continuous commands without --bins
  std::string BriefReport() const;
};

// Throws InputError naming file, line and column for bad input (unless drop_invalid for bad
// rows), or naming the option for options that do not fit the data (e.g. no overlap in time).
SampleSet ImportLog(const LogImportOptions& options, LogImportSummary* summary = nullptr);

}  // namespace dgmm
