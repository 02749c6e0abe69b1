#include "io/log_import.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <set>

#include "io/csv_reader.h"
#include "util/error.h"

namespace dgmm {
namespace {

using Interval = std::pair<double, double>;  // [begin, end] in seconds

// A parsed numeric stream: strictly increasing times (s) and one vector per column (SI units).
struct Series {
  std::string path;
  std::vector<double> t;
  std::vector<std::vector<double>> values;  // columns x rows
};

std::string Filename(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

double Unit(const LogImportOptions& o, const std::string& column) {
  auto it = o.units.find(column);
  return it == o.units.end() ? 1.0 : it->second;
}

// Reads a stream's time and value columns; rows with bad cells or times that do not increase
// are invalid (refused or dropped by `invalid`).
Series ReadSeries(const LogStream& stream, const LogImportOptions& o, InvalidRows* invalid,
                  long long* rows) {
  const CsvTable table = ReadCsv(stream.path, o.delimiter);
  const int time_col = table.Column(stream.time_column);
  std::vector<int> cols;
  for (const auto& c : stream.columns) cols.push_back(table.Column(c));
  Series s;
  s.path = stream.path;
  s.values.resize(cols.size());
  const double time_unit = Unit(o, stream.time_column);
  for (const CsvRecord& r : table.records) {
    try {
      table.CheckFieldCount(r);
      const double t = table.Number(r, time_col) * time_unit;
      if (!s.t.empty() && t <= s.t.back()) {
        throw MakeInputError(stream.path,
                             "line " + std::to_string(r.line) + ", column '" + stream.time_column + "'",
                             "time does not increase (expected rows sorted by time)");
      }
      std::vector<double> v;
      for (size_t j = 0; j < cols.size(); ++j) v.push_back(table.Number(r, cols[j]) * Unit(o, stream.columns[j]));
      s.t.push_back(t);
      for (size_t j = 0; j < cols.size(); ++j) s.values[j].push_back(v[j]);
    } catch (const InputError& e) {
      invalid->Handle(stream.path, e.what());
    }
  }
  *rows = static_cast<long long>(table.records.size());
  if (s.t.size() < 2) throw MakeInputError(stream.path, "", "fewer than 2 valid rows");
  return s;
}

// Replaces an angle series by its continuous version: each step is the shortest arc.
void Unwrap(std::vector<double>* a) {
  for (size_t i = 1; i < a->size(); ++i) {
    const double step = std::remainder((*a)[i] - (*a)[i - 1], 2 * std::numbers::pi);
    (*a)[i] = (*a)[i - 1] + step;
  }
}

// Index i with t[i] <= time <= t[i+1] and the fraction between them (time inside [t0, tn]).
std::pair<size_t, double> Bracket(const std::vector<double>& t, double time) {
  size_t i = std::upper_bound(t.begin(), t.end(), time) - t.begin();
  i = std::clamp<size_t>(i == 0 ? 0 : i - 1, 0, t.size() - 2);
  const double f = std::clamp((time - t[i]) / (t[i + 1] - t[i]), 0.0, 1.0);
  return {i, f};
}

double Lerp(const std::vector<double>& v, std::pair<size_t, double> b) {
  return v[b.first] + b.second * (v[b.first + 1] - v[b.first]);
}

double MedianInterval(const std::vector<double>& t) {
  std::vector<double> d;
  for (size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

// Runs of the stream with no pause longer than gap_s.
std::vector<Interval> Runs(const std::vector<double>& t, double gap_s) {
  std::vector<Interval> runs;
  size_t start = 0;
  for (size_t i = 1; i <= t.size(); ++i) {
    if (i == t.size() || t[i] - t[i - 1] > gap_s) {
      if (i - 1 > start) runs.push_back({t[start], t[i - 1]});
      start = i;
    }
  }
  return runs;
}

std::vector<Interval> Intersect(const std::vector<Interval>& a, const std::vector<Interval>& b) {
  std::vector<Interval> out;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double lo = std::max(a[i].first, b[j].first), hi = std::min(a[i].second, b[j].second);
    if (hi > lo) out.push_back({lo, hi});
    (a[i].second < b[j].second) ? ++i : ++j;
  }
  return out;
}

// Rz(yaw) Ry(pitch) Rx(roll) as a quaternion.
Eigen::Quaterniond FromRpy(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

// <roll, pitch, yaw> of R = Rz(yaw) Ry(pitch) Rx(roll), pitch in [-pi/2, pi/2].
Eigen::Vector3d ToRpy(const Eigen::Matrix3d& r) {
  return {std::atan2(r(2, 1), r(2, 2)), std::asin(std::clamp(-r(2, 0), -1.0, 1.0)),
          std::atan2(r(1, 0), r(0, 0))};
}

// The command stream: per valid row its time, the command key (numbers, bin centres or label
// codes) and label, and its episode id.
struct CommandRows {
  std::vector<double> t;
  std::vector<std::vector<double>> key;
  std::vector<std::string> label;
  std::vector<int> episode;
  std::vector<std::vector<std::string>> text;  // per row, per column: the label text or ""
};

std::string FormatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

CommandRows ReadCommands(const LogImportOptions& o, InvalidRows* invalid, long long* rows,
                         std::vector<std::string>* warnings) {
  const LogStream& s = o.commands;
  const CsvTable table = ReadCsv(s.path, o.delimiter);
  const int time_col = table.Column(s.time_column);
  const int episode_col = o.episode_column.empty() ? -1 : table.Column(o.episode_column);
  std::vector<int> cols;
  std::vector<bool> numeric;
  for (const auto& c : s.columns) {
    cols.push_back(table.Column(c));
    numeric.push_back(table.IsNumericColumn(cols.back()));
  }
  std::vector<std::map<std::string, int>> codes(cols.size());
  CommandRows out;
  std::vector<std::vector<double>> raw;  // numeric values before binning
  for (const CsvRecord& r : table.records) {
    try {
      table.CheckFieldCount(r);
      const double t = table.Number(r, time_col) * Unit(o, s.time_column);
      if (!out.t.empty() && t <= out.t.back()) {
        throw MakeInputError(s.path, "line " + std::to_string(r.line) + ", column '" + s.time_column + "'",
                             "time does not increase (expected rows sorted by time)");
      }
      std::vector<double> key;
      std::vector<std::string> text;
      for (size_t j = 0; j < cols.size(); ++j) {
        const std::string& cell = r.fields[cols[j]];
        text.push_back(numeric[j] ? "" : cell);
        if (numeric[j]) {
          key.push_back(table.Number(r, cols[j]) * Unit(o, s.columns[j]));
        } else {
          if (cell.empty()) {
            throw MakeInputError(s.path, "line " + std::to_string(r.line) + ", column '" + s.columns[j] + "'",
                                 "empty command label");
          }
          key.push_back(codes[j].try_emplace(cell, static_cast<int>(codes[j].size())).first->second);
        }
      }
      int episode = 0;
      if (episode_col >= 0) {
        const double e = table.Number(r, episode_col);
        if (e != std::floor(e) || std::abs(e) > 2e9) {
          throw MakeInputError(s.path, "line " + std::to_string(r.line) + ", column '" + o.episode_column + "'",
                               "episode id must be an integer");
        }
        episode = static_cast<int>(e);
      }
      out.t.push_back(t);
      out.key.push_back(key);
      out.text.push_back(text);
      out.episode.push_back(episode);
    } catch (const InputError& e) {
      invalid->Handle(s.path, e.what());
    }
  }
  *rows = static_cast<long long>(table.records.size());
  if (out.t.empty()) throw MakeInputError(s.path, "", "no valid command rows");
  // Numeric columns: bin (centres) when asked; labels are the (binned) values.
  for (size_t j = 0; j < cols.size(); ++j) {
    if (!numeric[j]) continue;
    if (o.bins == 0) {
      std::set<double> distinct;
      for (const auto& k : out.key) distinct.insert(k[j]);
      if (distinct.size() > 20 && distinct.size() * 10 > out.key.size()) {
        warnings->push_back("command column '" + s.columns[j] + "' has " +
                            std::to_string(distinct.size()) + " distinct values in " +
                            std::to_string(out.key.size()) +
                            " rows: continuous values? bin them with --bins");
      }
    }
    double lo = out.key[0][j], hi = lo;
    for (const auto& k : out.key) lo = std::min(lo, k[j]), hi = std::max(hi, k[j]);
    const double width = (hi - lo) / std::max(o.bins, 1);
    for (auto& k : out.key) {
      if (o.bins > 0 && width > 0) {
        const int b = std::min(static_cast<int>((k[j] - lo) / width), o.bins - 1);
        k[j] = lo + (b + 0.5) * width;
      }
    }
  }
  for (size_t i = 0; i < out.t.size(); ++i) {
    std::string label;
    for (size_t j = 0; j < cols.size(); ++j) {
      label += (j ? "," : "") + (numeric[j] ? FormatNumber(out.key[i][j]) : out.text[i][j]);
    }
    out.label.push_back(cols.empty() ? "all" : label);
  }
  return out;
}

}  // namespace

bool LogImportOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) { *error = m; return false; };
  if (commands.path.empty()) return fail("--commands: a command stream is required");
  if (pose.path.empty()) return fail("--pose: a pose stream is required");
  if (pose.columns.size() != 3 && pose.columns.size() != 6) {
    return fail("--pose-cols: " + std::to_string(pose.columns.size()) +
                " columns, expected 3 (x,y,yaw) or 6 (x,y,z,roll,pitch,yaw)");
  }
  if (commands.columns.empty() && episode_column.empty() && commands.path.empty()) {
    return fail("--command-cols: none chosen");
  }
  if (!attitude.path.empty() && attitude.columns.empty()) {
    return fail("--terrain-cols: none chosen for the attitude stream");
  }
  if (!(gap_s >= 0) || !std::isfinite(gap_s)) return fail("--gap: expected seconds >= 0");
  if (!(window_s >= 0) || !std::isfinite(window_s)) return fail("--window: expected seconds >= 0");
  if (!(min_duration_s >= 0) || !std::isfinite(min_duration_s)) return fail("--min-duration: expected seconds >= 0");
  if (bins < 0) return fail("--bins: expected >= 0");
  return true;
}

std::string LogImportSummary::BriefReport() const {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%d samples from %d episodes (%d command segments, %d shorter than %.3g s skipped; "
                "gap %.3g s); rows: %lld commands, %lld pose, %lld attitude, %lld dropped",
                samples, episodes, segments, short_segments, min_duration_s, gap_s, command_rows,
                pose_rows, attitude_rows, dropped_rows);
  return buf;
}

SampleSet ImportLog(const LogImportOptions& o, LogImportSummary* summary_out) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  LogImportSummary summary;
  InvalidRows invalid(o.drop_invalid);
  {
    std::set<std::string> known = {o.commands.time_column, o.pose.time_column, o.episode_column};
    for (const auto* s : {&o.commands, &o.pose, &o.attitude}) known.insert(s->columns.begin(), s->columns.end());
    if (!o.attitude.path.empty()) known.insert(o.attitude.time_column);
    for (const auto& [column, factor] : o.units) {
      if (!known.count(column)) {
        throw MakeInputError("", "--units", "column '" + column + "' is not a selected column");
      }
    }
  }
  const CommandRows commands = ReadCommands(o, &invalid, &summary.command_rows, &summary.warnings);
  Series pose = ReadSeries(o.pose, o, &invalid, &summary.pose_rows);
  const bool six_dof = pose.values.size() == 6;
  for (size_t j = six_dof ? 3 : 2; j < pose.values.size(); ++j) Unwrap(&pose.values[j]);
  const bool has_attitude = !o.attitude.path.empty();
  Series attitude;
  if (has_attitude) {
    attitude = ReadSeries(o.attitude, o, &invalid, &summary.attitude_rows);
    for (auto& column : attitude.values) Unwrap(&column);
  }

  // Episodes: sensor coverage without pauses longer than the gap, from the first command on;
  // with an episode column, also split where the id changes.
  double slowest = MedianInterval(pose.t);
  if (has_attitude) slowest = std::max(slowest, MedianInterval(attitude.t));
  summary.gap_s = o.gap_s > 0 ? o.gap_s : 10 * slowest;
  summary.min_duration_s =
      std::max(o.min_duration_s > 0 ? o.min_duration_s : 2 * MedianInterval(pose.t), o.window_s);
  std::vector<Interval> coverage = Runs(pose.t, summary.gap_s);
  if (has_attitude) coverage = Intersect(coverage, Runs(attitude.t, summary.gap_s));
  std::vector<Interval> command_spans;
  for (size_t i = 0, start = 0; i < commands.t.size(); ++i) {
    const bool last = i + 1 == commands.t.size() || commands.episode[i + 1] != commands.episode[i];
    if (!last) continue;
    // Without an episode column, the last command holds to the end of the sensor coverage.
    const double end = o.episode_column.empty() ? std::numeric_limits<double>::infinity()
                                                : commands.t[i];
    command_spans.push_back({commands.t[start], end});
    start = i + 1;
  }
  const std::vector<Interval> episodes = Intersect(coverage, command_spans);
  if (episodes.empty()) {
    throw MakeInputError(o.commands.path, "time",
                         "the command, pose and attitude streams do not overlap in time (check "
                         "their time columns and --units)");
  }

  SampleSet set;
  std::map<std::vector<double>, int> command_ids;
  std::vector<std::vector<double>> table_rows;
  std::vector<double> xs, zs;
  std::vector<int> sample_command, sample_episode, sample_step;
  std::set<std::string> all_labels(commands.label.begin(), commands.label.end()), used_labels;
  auto add_sample = [&](size_t row, double t0, double t1, int episode, int step) {
    const auto b0 = Bracket(pose.t, t0), b1 = Bracket(pose.t, t1);
    if (six_dof) {
      const Eigen::Vector3d p0(Lerp(pose.values[0], b0), Lerp(pose.values[1], b0), Lerp(pose.values[2], b0));
      const Eigen::Vector3d p1(Lerp(pose.values[0], b1), Lerp(pose.values[1], b1), Lerp(pose.values[2], b1));
      auto rotation = [&](std::pair<size_t, double> b) {
        auto q = [&](size_t i) { return FromRpy(pose.values[3][i], pose.values[4][i], pose.values[5][i]); };
        return q(b.first).slerp(b.second, q(b.first + 1));  // shortest arc
      };
      const Eigen::Quaterniond q0 = rotation(b0), q1 = rotation(b1);
      const Eigen::Vector3d dp = q0.conjugate() * (p1 - p0);
      const Eigen::Vector3d drpy = ToRpy((q0.conjugate() * q1).toRotationMatrix());
      xs.insert(xs.end(), {dp.x(), dp.y(), dp.z(), drpy.x(), drpy.y(), drpy.z()});
    } else {
      const double yaw0 = Lerp(pose.values[2], b0);
      const double dx = Lerp(pose.values[0], b1) - Lerp(pose.values[0], b0);
      const double dy = Lerp(pose.values[1], b1) - Lerp(pose.values[1], b0);
      xs.insert(xs.end(), {std::cos(yaw0) * dx + std::sin(yaw0) * dy,
                           -std::sin(yaw0) * dx + std::cos(yaw0) * dy,
                           Lerp(pose.values[2], b1) - yaw0});
    }
    if (has_attitude) {
      const auto ba = Bracket(attitude.t, t0);
      for (const auto& column : attitude.values) zs.push_back(std::remainder(Lerp(column, ba), 2 * std::numbers::pi));
    }
    auto [it, fresh] = command_ids.try_emplace(commands.key[row], static_cast<int>(table_rows.size()));
    if (fresh) {
      table_rows.push_back(commands.key[row]);
      set.command_labels.push_back(commands.label[row]);
    }
    used_labels.insert(commands.label[row]);
    sample_command.push_back(it->second);
    sample_episode.push_back(episode);
    sample_step.push_back(step);
  };

  // Durations within a quarter of the pose sampling interval of a window count as that window
  // (time stamps are rounded and jitter; the pose cannot tell them apart).
  const double tolerance = 0.25 * MedianInterval(pose.t);
  std::map<int, int> steps_so_far;
  for (size_t e = 0; e < episodes.size(); ++e) {
    const auto [a, b] = episodes[e];
    // Command row in force at a (a row issued before a logging gap is stale: then the episode
    // starts at its first command row), then each change of the command key until b.
    const auto after = std::upper_bound(commands.t.begin(), commands.t.end(), a);
    size_t row = static_cast<size_t>(after - commands.t.begin());
    double start = a;
    if (row > 0 && commands.t[row - 1] >= a - summary.gap_s) {
      --row;
    } else {
      if (row >= commands.t.size() || commands.t[row] >= b) continue;
      start = commands.t[row];
    }
    const int episode_id = o.episode_column.empty() ? static_cast<int>(e) : commands.episode[row];
    int& step = steps_so_far[episode_id];
    while (start < b) {
      size_t next = row + 1;
      while (next < commands.t.size() && commands.t[next] < b && commands.key[next] == commands.key[row]) ++next;
      const double end = next < commands.t.size() ? std::min(commands.t[next], b) : b;
      ++summary.segments;
      if (end - start < summary.min_duration_s - tolerance) {
        ++summary.short_segments;
      } else if (o.window_s > 0) {
        const int windows = static_cast<int>(std::floor((end - start + tolerance) / o.window_s));
        for (int w = 0; w < windows; ++w) {
          add_sample(row, start + w * o.window_s, std::min(end, start + (w + 1) * o.window_s),
                     episode_id, step++);
        }
      } else {
        add_sample(row, start, end, episode_id, step++);
      }
      if (next >= commands.t.size() || commands.t[next] >= b) break;
      row = next;
      start = end;
    }
  }
  summary.episodes = static_cast<int>(episodes.size());
  summary.samples = static_cast<int>(sample_command.size());
  summary.dropped_rows = invalid.total();
  summary.dropped_report = invalid.Report();
  for (const auto& label : all_labels) {
    if (!used_labels.count(label)) summary.unmatched_commands.push_back(label);
  }
  if (summary_out) *summary_out = summary;
  if (summary.samples == 0) {
    throw MakeInputError(o.commands.path, "",
                         "no samples: every command segment was shorter than " +
                             FormatNumber(summary.min_duration_s) +
                             " s (continuous commands need --bins) (" + summary.BriefReport() + ")");
  }

  const Eigen::Index n = summary.samples, dc = static_cast<Eigen::Index>(o.commands.columns.size());
  set.command_dim_names = o.commands.columns;
  set.commands.resize(static_cast<Eigen::Index>(table_rows.size()), dc);
  for (size_t r = 0; r < table_rows.size(); ++r) {
    for (Eigen::Index c = 0; c < dc; ++c) set.commands(r, c) = table_rows[r][c];
  }
  set.command = Eigen::Map<Eigen::VectorXi>(sample_command.data(), n);
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  set.x = Eigen::Map<RowMatrix>(xs.data(), n, six_dof ? 6 : 3);
  if (six_dof) {
    set.x_names = {"dx", "dy", "dz", "droll", "dpitch", "dyaw"};
    set.x_units = {"m", "m", "m", "rad", "rad", "rad"};
  } else {
    set.x_names = {"dx", "dy", "dyaw"};
    set.x_units = {"m", "m", "rad"};
  }
  if (has_attitude) {
    set.z = Eigen::Map<RowMatrix>(zs.data(), n, static_cast<Eigen::Index>(attitude.values.size()));
    // "pitch_deg" converted to radians is stored as "pitch".
    for (const std::string& name : o.attitude.columns) {
      std::string stored = name;
      for (const char* suffix : {"_deg", "_rad"}) {
        const std::string sfx = suffix;
        if (o.units.count(name) && name.size() > sfx.size() &&
            name.compare(name.size() - sfx.size(), sfx.size(), sfx) == 0) {
          stored = name.substr(0, name.size() - sfx.size());
        }
      }
      set.z_names.push_back(stored);
    }
    set.z_units.assign(attitude.values.size(), "rad");
  }
  set.episode = Eigen::Map<Eigen::VectorXi>(sample_episode.data(), n);
  set.step = Eigen::Map<Eigen::VectorXi>(sample_step.data(), n);
  set.source = o.source;
  std::string files = Filename(o.commands.path) + "," + Filename(o.pose.path);
  if (has_attitude) files += "," + Filename(o.attitude.path);
  set.metadata["imported_from"] = files;
  set.metadata["log_window_s"] = o.window_s > 0 ? FormatNumber(o.window_s) : "command segments";
  set.metadata["log_gap_s"] = FormatNumber(summary.gap_s);
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(o.commands.path, "", e);
  return set;
}

}  // namespace dgmm
