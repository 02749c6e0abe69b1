#include "io/log_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <set>

#include "core/set_warnings.h"
#include "io/csv_reader.h"
#include "io/log_files.h"
#include "io/log_time_series.h"
#include "util/error.h"

namespace dgmm {
namespace {

std::string Filename(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

double Unit(const LogImportOptions& o, const std::string& column) {
  auto it = o.units.find(column);
  return it == o.units.end() ? 1.0 : it->second;
}

std::string FormatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

// The time of record r (the index-th data row) in seconds: index / rate_hz when the stream has a
// rate, else its time column; InputError when it does not increase past `previous`.
double RowTime(const CsvTable& table, const CsvRecord& r, size_t index, int col,
               const LogStream& stream, const std::string& path, double unit,
               const std::vector<double>& previous) {
  if (stream.rate_hz > 0) return static_cast<double>(index) / stream.rate_hz;
  const double t = table.Number(r, col) * unit;
  if (!previous.empty() && t <= previous.back()) {
    throw MakeInputError(path,
                         "line " + std::to_string(r.line) + ", column '" + stream.time_column + "'",
                         "time does not increase (expected rows sorted by time)");
  }
  return t;
}

// Reads a stream file's time and value columns; rows with bad cells or times that do not increase
// are invalid (refused or dropped by `invalid`).
Series ReadSeries(const std::string& path, const LogStream& stream, const LogImportOptions& o,
                  InvalidRows* invalid, long long* rows) {
  const CsvTable table = ReadCsv(path, o.delimiter, o.has_header);
  const int time_col = stream.rate_hz > 0 ? -1 : table.Column(stream.time_column);
  std::vector<int> cols;
  for (const auto& c : stream.columns) cols.push_back(table.Column(c));
  Series s;
  s.path = path;
  s.values.resize(cols.size());
  for (size_t i = 0; i < table.records.size(); ++i) {
    const CsvRecord& r = table.records[i];
    try {
      table.CheckFieldCount(r);
      const double t =
          RowTime(table, r, i, time_col, stream, path, Unit(o, stream.time_column), s.t);
      std::vector<double> v;
      for (size_t j = 0; j < cols.size(); ++j) v.push_back(table.Number(r, cols[j]) * Unit(o, stream.columns[j]));
      s.t.push_back(t);
      for (size_t j = 0; j < cols.size(); ++j) s.values[j].push_back(v[j]);
    } catch (const InputError& e) {
      invalid->Handle(path, e.what());
    }
  }
  *rows += static_cast<long long>(table.records.size());
  if (s.t.size() < 2) throw MakeInputError(path, "", "fewer than 2 valid rows");
  return s;
}

// The command stream of one trial: per valid row its time, the command key (numbers, bin centres
// or label codes), its label and its episode id (from the episode column, else 0).
struct CommandRows {
  std::string path;
  std::vector<double> t;
  std::vector<std::vector<double>> key;
  std::vector<std::string> label;
  std::vector<int> episode;
  std::vector<std::vector<std::string>> text;  // per row, per column: the label text or ""
  std::vector<std::vector<double>> continuous;  // per row, the continuous command columns (SI)
};

// What all trials share about the command columns: which are numeric (decided by the first file)
// and the codes of text labels, so that one label is one command in every trial.
struct CommandColumns {
  std::vector<int> numeric;  // -1 unknown yet, 0 text, 1 numbers
  std::vector<std::map<std::string, int>> codes;
};

// The command keys of one row; InputError for an empty label.
std::vector<double> RowKey(const CsvTable& table, const CsvRecord& r, const std::vector<int>& cols,
                           const LogImportOptions& o, const std::string& path,
                           CommandColumns* shared, std::vector<std::string>* text) {
  std::vector<double> key;
  for (size_t j = 0; j < cols.size(); ++j) {
    const std::string& cell = r.fields[cols[j]];
    const bool numeric = shared->numeric[j] == 1;
    text->push_back(numeric ? "" : cell);
    if (numeric) {
      key.push_back(table.Number(r, cols[j]) * Unit(o, o.commands.columns[j]));
      continue;
    }
    if (cell.empty()) {
      throw MakeInputError(
          path, "line " + std::to_string(r.line) + ", column '" + o.commands.columns[j] + "'",
          "empty command label");
    }
    key.push_back(shared->codes[j]
                      .try_emplace(cell, static_cast<int>(shared->codes[j].size()))
                      .first->second);
  }
  return key;
}

CommandRows ReadCommands(const std::string& path, const LogImportOptions& o, CommandColumns* shared,
                         InvalidRows* invalid, long long* rows) {
  const LogStream& s = o.commands;
  const CsvTable table = ReadCsv(path, o.delimiter, o.has_header);
  const int time_col = s.rate_hz > 0 ? -1 : table.Column(s.time_column);
  const int episode_col = o.episode_column.empty() ? -1 : table.Column(o.episode_column);
  std::vector<int> cols;
  for (size_t j = 0; j < s.columns.size(); ++j) {
    cols.push_back(table.Column(s.columns[j]));
    const int numeric = table.IsNumericColumn(cols.back()) ? 1 : 0;
    if (shared->numeric[j] < 0) shared->numeric[j] = numeric;
    if (shared->numeric[j] != numeric) {
      throw MakeInputError(path, "column '" + s.columns[j] + "'",
                           numeric ? "numbers here but text labels in an earlier file"
                                   : "text labels here but numbers in an earlier file");
    }
  }
  std::vector<int> continuous_cols;
  for (const std::string& name : o.continuous_columns) {
    continuous_cols.push_back(table.Column(name));
    if (!table.IsNumericColumn(continuous_cols.back())) {
      throw MakeInputError(path, "column '" + name + "'",
                           "a continuous command column must hold numbers");
    }
  }
  CommandRows out;
  out.path = path;
  for (size_t i = 0; i < table.records.size(); ++i) {
    const CsvRecord& r = table.records[i];
    try {
      table.CheckFieldCount(r);
      const double t = RowTime(table, r, i, time_col, s, path, Unit(o, s.time_column), out.t);
      std::vector<std::string> text;
      std::vector<double> key = RowKey(table, r, cols, o, path, shared, &text);
      std::vector<double> continuous;
      for (size_t j = 0; j < continuous_cols.size(); ++j) {
        continuous.push_back(table.Number(r, continuous_cols[j]) *
                             Unit(o, o.continuous_columns[j]));
      }
      int episode = 0;
      if (episode_col >= 0) {
        const double e = table.Number(r, episode_col);
        if (e != std::floor(e) || std::abs(e) > 2e9) {
          throw MakeInputError(
              path, "line " + std::to_string(r.line) + ", column '" + o.episode_column + "'",
              "episode id must be an integer");
        }
        episode = static_cast<int>(e);
      }
      out.t.push_back(t);
      out.key.push_back(std::move(key));
      out.text.push_back(std::move(text));
      out.continuous.push_back(std::move(continuous));
      out.episode.push_back(episode);
    } catch (const InputError& e) {
      invalid->Handle(path, e.what());
    }
  }
  *rows += static_cast<long long>(table.records.size());
  if (out.t.empty()) throw MakeInputError(path, "", "no valid command rows");
  return out;
}

// Numeric command columns of every trial: binned when asked (io/command_bins.h, over all trials
// at once), else a warning when they look continuous. Then each row's label.
void KeyCommands(const LogImportOptions& o, const CommandColumns& shared,
                 std::vector<CommandRows>* trials, std::vector<std::string>* warnings) {
  const bool binning = o.bins.bins > 0 || !o.bins.edges.empty();
  for (size_t j = 0; j < o.commands.columns.size(); ++j) {
    if (shared.numeric[j] != 1) continue;
    std::vector<double> values;
    for (const CommandRows& c : *trials) {
      for (const auto& k : c.key) values.push_back(k[j]);
    }
    if (binning) {
      const std::vector<double> binned = BinCommandValues(values, o.bins);
      size_t i = 0;
      for (CommandRows& c : *trials) {
        for (auto& k : c.key) k[j] = binned[i++];
      }
      continue;
    }
    const std::set<double> distinct(values.begin(), values.end());
    if (distinct.size() > 20 && distinct.size() * 10 > values.size()) {
      warnings->push_back("command column '" + o.commands.columns[j] + "' has " +
                          std::to_string(distinct.size()) + " distinct values in " +
                          std::to_string(values.size()) +
                          " rows: continuous values? keep them as they are with --continuous-cols "
                          "and --window, or bin them with --bins N (quantiles; zero is its own "
                          "command) or --bin-edges");
    }
  }
  for (CommandRows& c : *trials) {
    for (size_t i = 0; i < c.t.size(); ++i) {
      std::string label;
      for (size_t j = 0; j < o.commands.columns.size(); ++j) {
        label +=
            (j ? "," : "") + (shared.numeric[j] == 1 ? FormatNumber(c.key[i][j]) : c.text[i][j]);
      }
      c.label.push_back(o.commands.columns.empty() ? "all" : label);
    }
  }
}

// The pose and attitude of one trial, angles unwrapped.
struct TrialStreams {
  Series pose, attitude;
  bool six_dof = false, has_attitude = false;
};

TrialStreams ReadStreams(const LogTrial& trial, const LogImportOptions& o, InvalidRows* invalid,
                         LogImportSummary* summary) {
  TrialStreams s;
  s.pose = ReadSeries(trial.pose, o.pose, o, invalid, &summary->pose_rows);
  s.six_dof = s.pose.values.size() == 6;
  for (size_t j = s.six_dof ? 3 : 2; j < s.pose.values.size(); ++j) Unwrap(&s.pose.values[j]);
  s.has_attitude = !trial.attitude.empty();
  if (s.has_attitude) {
    s.attitude = ReadSeries(trial.attitude, o.attitude, o, invalid, &summary->attitude_rows);
    for (auto& column : s.attitude.values) Unwrap(&column);
  }
  return s;
}

// The samples as they are cut: pose changes, terrain, command table, episode and step.
struct SampleSink {
  SampleSet set;
  std::map<std::vector<double>, int> command_ids;
  std::vector<std::vector<double>> table_rows;
  std::vector<double> xs, zs, durations;
  std::vector<int> command, episode, step;
  std::set<std::string> used_labels;
  // Per continuous command column: each window's time average and its variation inside.
  std::vector<std::vector<double>> continuous_mean, continuous_within;

  // The pose change over [t0, t1] in the body frame at t0 (and the terrain at t0) for `row`.
  void Add(const CommandRows& c, size_t row, const TrialStreams& s, double t0, double t1,
           int episode_id, int step_in_episode, bool per_second);
  // The continuous command columns' time averages over [t0, t1] (first conditioning dimensions
  // of z) and their variation inside the window; the command row in force at t0 is `row` or
  // later (rows hold until the next).
  void AddContinuous(const CommandRows& c, size_t row, double t0, double t1);
};

void SampleSink::AddContinuous(const CommandRows& c, size_t row, double t0, double t1) {
  const size_t dims = c.continuous.empty() ? 0 : c.continuous[0].size();
  if (dims == 0) return;
  continuous_mean.resize(dims);
  continuous_within.resize(dims);
  while (row + 1 < c.t.size() && c.t[row + 1] <= t0) ++row;
  // The rows in force and w_i, the time each holds inside [t0, t1].
  std::vector<double> w;
  double total = 0;
  for (size_t i = row; i < c.t.size() && (i == row || c.t[i] < t1); ++i) {
    const double hi = i + 1 < c.t.size() ? std::min(c.t[i + 1], t1) : t1;
    w.push_back(std::max(0.0, hi - std::max(c.t[i], t0)));
    total += w.back();
  }
  // Mean, then the variation around it (two passes: no cancellation for values far from 0).
  for (size_t j = 0; j < dims; ++j) {
    double mean = c.continuous[row][j], var = 0;
    if (total > 0) {
      mean = 0;
      for (size_t k = 0; k < w.size(); ++k) mean += w[k] * c.continuous[row + k][j];
      mean /= total;
      for (size_t k = 0; k < w.size(); ++k) {
        const double e = c.continuous[row + k][j] - mean;
        var += w[k] * e * e;
      }
      var /= total;
    }
    zs.push_back(mean);
    continuous_mean[j].push_back(mean);
    continuous_within[j].push_back(std::sqrt(var));
  }
}

void SampleSink::Add(const CommandRows& c, size_t row, const TrialStreams& s, double t0, double t1,
                     int episode_id, int step_in_episode, bool per_second) {
  const Series& pose = s.pose;
  // The duration the pose change covers (the pose is held at the stream's ends).
  const double duration =
      std::clamp(t1, pose.t.front(), pose.t.back()) - std::clamp(t0, pose.t.front(), pose.t.back());
  const size_t first = xs.size();
  const Eigen::VectorXd dx = BodyFramePoseChange(pose, t0, t1);
  xs.insert(xs.end(), dx.data(), dx.data() + dx.size());
  if (per_second) {
    for (size_t i = first; i < xs.size(); ++i) xs[i] /= std::max(duration, 1e-12);
  }
  AddContinuous(c, row, t0, t1);
  if (s.has_attitude) {
    const auto ba = Bracket(s.attitude.t, t0);
    for (const auto& column : s.attitude.values)
      zs.push_back(std::remainder(Lerp(column, ba), 2 * std::numbers::pi));
  }
  auto [it, fresh] = command_ids.try_emplace(c.key[row], static_cast<int>(table_rows.size()));
  if (fresh) {
    table_rows.push_back(c.key[row]);
    set.command_labels.push_back(c.label[row]);
  }
  used_labels.insert(c.label[row]);
  command.push_back(it->second);
  episode.push_back(episode_id);
  step.push_back(step_in_episode);
  durations.push_back(duration);
}

// The time scales every trial shares: median pose interval, and the automatic gap, minimum
// duration and tolerance derived from it.
struct TimeScales {
  double pose_dt = 0, gap = 0, min_duration = 0, tolerance = 0;
};

TimeScales MakeTimeScales(const std::vector<TrialStreams>& streams, const LogImportOptions& o) {
  std::vector<double> pose_dt, attitude_dt;
  for (const TrialStreams& s : streams) {
    pose_dt.push_back(MedianInterval(s.pose.t));
    if (s.has_attitude) attitude_dt.push_back(MedianInterval(s.attitude.t));
  }
  TimeScales ts;
  ts.pose_dt = Median(pose_dt);
  const double slowest = std::max(ts.pose_dt, Median(attitude_dt));
  ts.gap = o.gap_s > 0 ? o.gap_s : 10 * slowest;
  ts.min_duration = std::max(o.min_duration_s > 0 ? o.min_duration_s : 2 * ts.pose_dt, o.window_s);
  ts.tolerance = o.time_tolerance_s > 0 ? o.time_tolerance_s : 0.5 * ts.pose_dt;
  return ts;
}

// The episodes of one trial: sensor coverage without pauses longer than the gap, from the first
// command on; with an episode column, also split where the id changes.
std::vector<Interval> TrialEpisodes(const CommandRows& c, const TrialStreams& s,
                                    const LogImportOptions& o, double gap) {
  std::vector<Interval> coverage = Runs(s.pose.t, gap);
  if (s.has_attitude) coverage = Intersect(coverage, Runs(s.attitude.t, gap));
  std::vector<Interval> command_spans;
  for (size_t i = 0, start = 0; i < c.t.size(); ++i) {
    const bool last = i + 1 == c.t.size() || c.episode[i + 1] != c.episode[i];
    if (!last) continue;
    // Without an episode column, the last command holds to the end of the sensor coverage.
    const double end = o.episode_column.empty() ? std::numeric_limits<double>::infinity() : c.t[i];
    command_spans.push_back({c.t[start], end});
    start = i + 1;
  }
  return Intersect(coverage, command_spans);
}

// Command rows whose hold [t_i, t_{i+1}) meets no episode: logged while the pose (or attitude)
// was not.
long long RowsOutside(const CommandRows& c, const std::vector<Interval>& episodes) {
  long long outside = 0;
  for (size_t i = 0; i < c.t.size(); ++i) {
    const double hi = i + 1 < c.t.size() ? c.t[i + 1] : std::numeric_limits<double>::infinity();
    const bool meets = std::any_of(episodes.begin(), episodes.end(), [&](const Interval& e) {
      return c.t[i] < e.second && hi > e.first;
    });
    outside += !meets;
  }
  return outside;
}

// Where a trial's samples go: episode ids (per trial, per gap or per episode-column value).
struct EpisodeIds {
  bool several_trials = false;
  int trial = 0;
  std::map<std::pair<int, int>, int>* by_column;  // (trial, column id) -> global id
  int next_gap_episode = 0;
  int Id(const LogImportOptions& o, const CommandRows& c, size_t row) {
    if (!o.episode_column.empty()) {
      if (!several_trials) return c.episode[row];
      return by_column->try_emplace({trial, c.episode[row]}, static_cast<int>(by_column->size()))
          .first->second;
    }
    return several_trials ? trial : next_gap_episode++;
  }
};

// One command segment [start, end]: skipped when too short, else one sample or whole windows.
void CutSegment(const CommandRows& c, size_t row, const TrialStreams& s, double start, double end,
                int episode_id, int* step, const LogImportOptions& o, const TimeScales& ts,
                LogImportSummary* summary, SampleSink* sink) {
  constexpr double kRelativeEpsilon = 1e-9;
  // Each end of a window may lie up to the tolerance beyond the data (the pose held there): a
  // segment one pose interval short of a window still makes it at the default tolerance.
  const double slack = 2 * ts.tolerance;
  const double length = end - start;
  ++summary->segments;
  const double window = o.window_s > 0 ? o.window_s : length;
  const int windows =
      length + slack < ts.min_duration
          ? 0
          : static_cast<int>(std::floor((length + slack) / window + kRelativeEpsilon));
  if (windows == 0) ++summary->short_segments;
  for (int w = 0; w < windows; ++w) {
    sink->Add(c, row, s, start + w * window, std::min(end, start + (w + 1) * window), episode_id,
              (*step)++, o.per_second);
  }
  if (o.window_s <= 0) return;
  const double remainder = length - windows * window;
  if (remainder > slack) {
    if (windows > 0) ++summary->remainders;
    const double shortfall = window - remainder;
    if (shortfall <= 2 * ts.pose_dt) {
      ++summary->near_miss_remainders;
      summary->largest_near_miss_s = std::max(summary->largest_near_miss_s, shortfall);
    }
  }
}

// Cuts one trial's episodes at command changes (and into windows).
void CutTrial(const CommandRows& c, const TrialStreams& s, const std::vector<Interval>& episodes,
              const LogImportOptions& o, const TimeScales& ts, EpisodeIds* ids,
              std::map<int, int>* steps_so_far, LogImportSummary* summary, SampleSink* sink) {
  for (const auto& [a, b] : episodes) {
    // Command row in force at a (a row issued before a logging gap is stale: then the episode
    // starts at its first command row), then each change of the command key until b.
    const auto after = std::upper_bound(c.t.begin(), c.t.end(), a);
    size_t row = static_cast<size_t>(after - c.t.begin());
    double start = a;
    if (row > 0 && c.t[row - 1] >= a - ts.gap) {
      --row;
    } else {
      if (row >= c.t.size() || c.t[row] >= b) continue;
      start = c.t[row];
    }
    const int episode_id = ids->Id(o, c, row);
    int& step = (*steps_so_far)[episode_id];
    while (start < b) {
      size_t next = row + 1;
      while (next < c.t.size() && c.t[next] < b && c.key[next] == c.key[row]) ++next;
      const double end = next < c.t.size() ? std::min(c.t[next], b) : b;
      CutSegment(c, row, s, start, end, episode_id, &step, o, ts, summary, sink);
      if (next >= c.t.size() || c.t[next] >= b) break;
      row = next;
      start = end;
    }
  }
}

// Warnings about the samples' durations: unequal durations make pose changes incomparable.
void CheckDurations(const std::vector<double>& durations, const LogImportOptions& o,
                    const TimeScales& ts, LogImportSummary* summary) {
  if (durations.empty()) return;
  const auto [lo, hi] = std::minmax_element(durations.begin(), durations.end());
  summary->min_window_s = *lo;
  summary->max_window_s = *hi;
  summary->median_window_s = Median(durations);
  // Windows shortened by up to the tolerance at each end are expected; more than that is not.
  const double expected = std::max(2 * ts.tolerance, 0.02 * summary->median_window_s) * 1.01;
  if (o.per_second || *hi - *lo <= expected) return;
  summary->warnings.push_back(
      "samples last from " + FormatNumber(*lo) + " to " + FormatNumber(*hi) + " s (median " +
      FormatNumber(summary->median_window_s) +
      " s) and the pose change grows with duration: cut equal windows with --window S, or divide "
      "by the duration with --per-second");
}

void CheckUnits(const LogImportOptions& o) {
  std::set<std::string> known = {o.commands.time_column, o.pose.time_column, o.episode_column};
  for (const auto* s : {&o.commands, &o.pose, &o.attitude})
    known.insert(s->columns.begin(), s->columns.end());
  known.insert(o.continuous_columns.begin(), o.continuous_columns.end());
  if (!o.attitude.path.empty()) known.insert(o.attitude.time_column);
  for (const auto& [column, factor] : o.units) {
    if (!known.count(column)) {
      throw MakeInputError("", "--units", "column '" + column + "' is not a selected column");
    }
  }
}

// The set from the sink: command table, x (and z), names and units, episodes, metadata.
SampleSet Assemble(SampleSink& sink, const LogImportOptions& o, const std::vector<LogTrial>& trials,
                   const LogImportSummary& summary, bool six_dof, int terrain_dims) {
  SampleSet set = std::move(sink.set);
  const Eigen::Index n = summary.samples, dc = static_cast<Eigen::Index>(o.commands.columns.size());
  set.command_dim_names = o.commands.columns;
  set.commands.resize(static_cast<Eigen::Index>(sink.table_rows.size()), dc);
  for (size_t r = 0; r < sink.table_rows.size(); ++r) {
    for (Eigen::Index c = 0; c < dc; ++c) set.commands(r, c) = sink.table_rows[r][c];
  }
  set.command = Eigen::Map<Eigen::VectorXi>(sink.command.data(), n);
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  set.x = Eigen::Map<RowMatrix>(sink.xs.data(), n, six_dof ? 6 : 3);
  const std::string rate = o.per_second ? "/s" : "";
  if (six_dof) {
    set.x_names = {"dx", "dy", "dz", "droll", "dpitch", "dyaw"};
    set.x_units = {"m" + rate, "m" + rate, "m" + rate, "rad" + rate, "rad" + rate, "rad" + rate};
  } else {
    set.x_names = {"dx", "dy", "dyaw"};
    set.x_units = {"m" + rate, "m" + rate, "rad" + rate};
  }
  const int continuous_dims = static_cast<int>(o.continuous_columns.size());
  for (const std::string& name : o.continuous_columns) {
    set.z_names.push_back(name);
    set.z_units.push_back(o.units.count(name) ? "SI" : "as logged");
  }
  if (continuous_dims > 0) {
    set.metadata["continuous_command_columns"] = std::to_string(continuous_dims);
  }
  if (terrain_dims + continuous_dims > 0) {
    set.z = Eigen::Map<RowMatrix>(sink.zs.data(), n, terrain_dims + continuous_dims);
  }
  if (terrain_dims > 0) {
    // "pitch_deg" converted to radians is stored as "pitch".
    for (const std::string& name : o.attitude.columns) {
      std::string stored = name;
      for (const std::string sfx : {"_deg", "_rad"}) {
        if (o.units.count(name) && name.size() > sfx.size() &&
            name.compare(name.size() - sfx.size(), sfx.size(), sfx) == 0) {
          stored = name.substr(0, name.size() - sfx.size());
        }
      }
      set.z_names.push_back(stored);
    }
    set.z_units.resize(continuous_dims + terrain_dims, "rad");
  }
  set.episode = Eigen::Map<Eigen::VectorXi>(sink.episode.data(), n);
  set.step = Eigen::Map<Eigen::VectorXi>(sink.step.data(), n);
  set.source = o.source;
  std::string files = Filename(trials[0].commands) + "," + Filename(trials[0].pose);
  if (!trials[0].attitude.empty()) files += "," + Filename(trials[0].attitude);
  if (trials.size() > 1) files += " and " + std::to_string(trials.size() - 1) + " more trials";
  set.metadata["imported_from"] = files;
  set.metadata["log_window_s"] = o.window_s > 0 ? FormatNumber(o.window_s) : "command segments";
  set.metadata["log_gap_s"] = FormatNumber(summary.gap_s);
  if (o.per_second) set.metadata["log_per_second"] = "pose changes divided by window duration";
  KeepWarnings(summary.warnings, &set);
  return set;
}

}  // namespace

bool LogImportOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    *error = m;
    return false;
  };
  if (commands.path.empty()) return fail("--commands: a command stream is required");
  if (pose.path.empty()) return fail("--pose: a pose stream is required");
  if (pose.columns.size() != 3 && pose.columns.size() != 6) {
    return fail("--pose-cols: " + std::to_string(pose.columns.size()) +
                " columns, expected 3 (x,y,yaw) or 6 (x,y,z,roll,pitch,yaw)");
  }
  if (!attitude.path.empty() && attitude.columns.empty()) {
    return fail("--terrain-cols: none chosen for the attitude stream");
  }
  if (attitude.path.empty() && !attitude.columns.empty()) {
    return fail("--terrain-cols: given without an --attitude stream to read them from");
  }
  if (!(gap_s >= 0) || !std::isfinite(gap_s)) return fail("--gap: expected seconds >= 0");
  if (!(window_s >= 0) || !std::isfinite(window_s)) return fail("--window: expected seconds >= 0");
  if (!(min_duration_s >= 0) || !std::isfinite(min_duration_s))
    return fail("--min-duration: expected seconds >= 0");
  for (const auto& [stream, flag] : {std::pair{&commands, "--commands-rate"},
                                     {&pose, "--pose-rate"},
                                     {&attitude, "--attitude-rate"}}) {
    if (!(stream->rate_hz >= 0) || !std::isfinite(stream->rate_hz)) {
      return fail(std::string(flag) + ": expected rows per second >= 0");
    }
  }
  if (!(time_tolerance_s >= 0) || !std::isfinite(time_tolerance_s)) {
    return fail("--time-tolerance: expected seconds >= 0");
  }
  if (!continuous_columns.empty() && window_s <= 0) {
    return fail("--continuous-cols: needs --window S (each window keeps the commands' average)");
  }
  for (const std::string& name : continuous_columns) {
    if (std::find(commands.columns.begin(), commands.columns.end(), name) !=
        commands.columns.end()) {
      return fail("--continuous-cols: '" + name + "' is also a --command-cols column");
    }
  }
  if (window_s > 0 && 2 * time_tolerance_s >= window_s) {
    return fail(
        "--time-tolerance: must be shorter than half the --window (it applies at each end)");
  }
  return bins.IsValid(error);
}

std::string LogImportSummary::BriefReport() const {
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%d samples from %d episodes%s (%d command segments, %d shorter than %.3g s skipped; "
      "gap %.3g s); rows: %lld commands, %lld pose, %lld attitude, %lld dropped",
      samples, episodes, trials > 1 ? (" in " + std::to_string(trials) + " trials").c_str() : "",
      segments, short_segments, min_duration_s, gap_s, command_rows, pose_rows, attitude_rows,
      dropped_rows);
  return buf;
}

std::string LogImportSummary::WindowReport() const {
  std::string dropped;
  auto add = [&](long long n, const std::string& what) {
    if (n > 0) dropped += (dropped.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(short_segments, "command segments shorter than " + FormatNumber(min_duration_s) + " s");
  add(remainders, "segment remainders shorter than a window");
  add(commands_outside_coverage, "command rows outside the pose" +
                                     std::string(attitude_rows > 0 ? "/attitude" : "") +
                                     " coverage");
  add(trials_without_overlap, "trials whose streams do not overlap in time");
  add(dropped_rows, "invalid rows");
  std::string out = "windows: " + std::to_string(samples) +
                    " kept; dropped: " + (dropped.empty() ? "none" : dropped);
  if (near_miss_remainders > 0) {
    out += "; " + std::to_string(near_miss_remainders) +
           " of them fell short of a window by at most " + FormatNumber(largest_near_miss_s) +
           " s (time tolerance " + FormatNumber(time_tolerance_s) +
           " s at each end of a window; keep them with --time-tolerance " +
           FormatNumber(0.5 * largest_near_miss_s * 1.01) + ")";
  }
  return out;
}

std::string LogImportSummary::ContinuousReport() const {
  std::string out;
  for (const ContinuousColumn& c : continuous) {
    out += (out.empty() ? "" : "\n") + std::string("continuous command ") + c.name + ": " +
           FormatNumber(c.min) + " to " + FormatNumber(c.max) + ", window averages spread " +
           FormatNumber(c.spread) + " (standard deviation), variation inside a window " +
           FormatNumber(c.median_within) + " (median standard deviation)";
  }
  return out;
}

// Range and spread of each continuous column's window averages and the median variation inside.
void SummariseContinuous(const LogImportOptions& o, const SampleSink& sink,
                         LogImportSummary* summary) {
  for (size_t j = 0; j < sink.continuous_mean.size(); ++j) {
    const std::vector<double>& m = sink.continuous_mean[j];
    LogImportSummary::ContinuousColumn c;
    c.name = o.continuous_columns[j];
    const auto [lo, hi] = std::minmax_element(m.begin(), m.end());
    c.min = *lo, c.max = *hi;
    const Eigen::Map<const Eigen::ArrayXd> a(m.data(), static_cast<Eigen::Index>(m.size()));
    c.spread = m.size() > 1 ? std::sqrt((a - a.mean()).square().sum() / (a.size() - 1.0)) : 0.0;
    c.median_within = Median(sink.continuous_within[j]);
    summary->continuous.push_back(c);
  }
}

SampleSet ImportLog(const LogImportOptions& o, LogImportSummary* summary_out) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  CheckUnits(o);
  LogImportSummary summary;
  InvalidRows invalid(o.drop_invalid);
  const std::vector<LogTrial> trials = PairTrials(
      ResolveStreamFiles(o.commands.path, "--commands"), ResolveStreamFiles(o.pose.path, "--pose"),
      o.attitude.path.empty() ? std::vector<std::string>{}
                              : ResolveStreamFiles(o.attitude.path, "--attitude"));
  summary.trials = static_cast<int>(trials.size());
  // Commands of every trial first (labels and bins are shared), then the sensor streams.
  CommandColumns shared{std::vector<int>(o.commands.columns.size(), -1),
                        std::vector<std::map<std::string, int>>(o.commands.columns.size())};
  std::vector<CommandRows> commands;
  for (const LogTrial& t : trials) {
    commands.push_back(ReadCommands(t.commands, o, &shared, &invalid, &summary.command_rows));
  }
  KeyCommands(o, shared, &commands, &summary.warnings);
  std::vector<TrialStreams> streams;
  for (const LogTrial& t : trials) streams.push_back(ReadStreams(t, o, &invalid, &summary));
  const TimeScales ts = MakeTimeScales(streams, o);
  summary.gap_s = ts.gap;
  summary.min_duration_s = ts.min_duration;
  summary.time_tolerance_s = ts.tolerance;

  SampleSink sink;
  std::map<std::pair<int, int>, int> by_column;
  std::map<int, int> steps_so_far;
  for (size_t i = 0; i < trials.size(); ++i) {
    const std::vector<Interval> episodes = TrialEpisodes(commands[i], streams[i], o, ts.gap);
    summary.episodes += trials.size() > 1 && o.episode_column.empty() && !episodes.empty()
                            ? 1
                            : static_cast<int>(episodes.size());
    summary.commands_outside_coverage += RowsOutside(commands[i], episodes);
    summary.trials_without_overlap += episodes.empty();
    EpisodeIds ids{trials.size() > 1, static_cast<int>(i), &by_column};
    CutTrial(commands[i], streams[i], episodes, o, ts, &ids, &steps_so_far, &summary, &sink);
  }
  if (summary.episodes == 0) {
    throw MakeInputError(trials[0].commands, "time",
                         "the command, pose and attitude streams do not overlap in time (check "
                         "their time columns and --units)");
  }
  summary.samples = static_cast<int>(sink.command.size());
  summary.dropped_rows = invalid.total();
  summary.dropped_report = invalid.Report();
  std::set<std::string> all_labels;
  for (const CommandRows& c : commands) all_labels.insert(c.label.begin(), c.label.end());
  for (const auto& label : all_labels) {
    if (!sink.used_labels.count(label)) summary.unmatched_commands.push_back(label);
  }
  CheckDurations(sink.durations, o, ts, &summary);
  if (summary.samples > 0) SummariseContinuous(o, sink, &summary);
  if (summary_out) *summary_out = summary;
  if (summary.samples == 0) {
    throw MakeInputError(trials[0].commands, "",
                         "no samples: every command segment was shorter than " +
                             FormatNumber(summary.min_duration_s) +
                             " s (continuous commands: --continuous-cols with --window, or --bins) (" +
                             summary.WindowReport() +
                             ")");
  }
  SampleSet set =
      Assemble(sink, o, trials, summary, streams[0].six_dof,
               streams[0].has_attitude ? static_cast<int>(o.attitude.columns.size()) : 0);
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(trials[0].commands, "", e);
  return set;
}

}  // namespace dgmm
