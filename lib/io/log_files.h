#pragma once
// Which CSV files make up a log: one file per stream, or several per stream (a folder or a glob
// pattern), one per trial. Files of different streams belong to the same trial when the parts of
// their names that differ within each stream agree: commands/cmd_07.csv, pose/pose_07.csv and
// trial07/imu.csv all belong to trial "7" (numbers compare as numbers).
#include <string>
#include <vector>

namespace dgmm {

// The CSV files a stream option names, sorted: the file itself, the *.csv files of a folder, or
// the matches of a glob pattern (*, ?, [...], {a,b}). InputError naming `flag` and the path when
// nothing matches.
std::vector<std::string> ResolveStreamFiles(const std::string& path, const std::string& flag);

// One trial: a file of each stream (attitude empty when there is no attitude stream).
struct LogTrial {
  std::string name;  // what tells this trial's files apart ("" when each stream has one file)
  std::string commands, pose, attitude;
};

// The trials of the streams' files (attitude may be empty: no attitude stream). One file per
// stream: one trial. Otherwise every stream must have one file per trial, paired by name;
// InputError naming the flag and the first file without a partner otherwise.
std::vector<LogTrial> PairTrials(const std::vector<std::string>& commands,
                                 const std::vector<std::string>& pose,
                                 const std::vector<std::string>& attitude);

// The part of each name that differs from the others (common prefix and suffix removed, never
// splitting a number; numbers without leading zeros): {"a/cmd_07.csv", "a/cmd_10.csv"} -> {"7",
// "10"}. One name: {""}.
std::vector<std::string> TrialKeys(const std::vector<std::string>& names);

}  // namespace dgmm
