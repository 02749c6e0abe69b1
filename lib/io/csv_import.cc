#include "io/csv_import.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>

#include "io/csv_reader.h"
#include "util/error.h"

namespace dgmm {
namespace {

// Column index of each name; InputError for unknown or twice-selected names.
std::vector<int> FindColumns(const std::vector<std::string>& wanted, const CsvTable& table,
                             std::set<std::string>* used) {
  std::vector<int> indices;
  for (const std::string& name : wanted) {
    indices.push_back(table.Column(name));
    if (!used->insert(name).second) {
      throw MakeInputError(table.path, "column '" + name + "'", "selected twice");
    }
  }
  return indices;
}

// Mean and population standard deviation per column of y = x || z; scale 1 where sd is 0.
Standardization Standardize(Eigen::MatrixXd* x, Eigen::MatrixXd* z) {
  const Eigen::Index dx = x->cols(), dz = z->cols(), n = x->rows();
  Standardization t;
  t.offset.resize(dx + dz);
  t.scale.resize(dx + dz);
  for (Eigen::Index j = 0; j < dx + dz; ++j) {
    auto column = j < dx ? x->col(j) : z->col(j - dx);
    // In units of the largest magnitude m, so that sums of values near 1e308 cannot overflow.
    const double m = column.cwiseAbs().maxCoeff();
    const double unit = m > 0 ? m : 1.0;
    const Eigen::ArrayXd u = column.array() / unit;
    const double mean_u = u.mean();
    const double sd_u = std::sqrt((u - mean_u).square().sum() / static_cast<double>(n));
    const double scale_u = sd_u > 0 ? sd_u : 1.0 / unit;  // a constant column keeps scale 1
    column = ((u - mean_u) / scale_u).matrix();
    t.offset[j] = mean_u * unit;
    t.scale[j] = scale_u * unit;
  }
  return t;
}

// The chosen columns of a table, their unit factors and which command columns hold text labels.
struct ColumnPlan {
  std::vector<int> command, pose, conditioning, episode;  // episode: empty or one column
  std::vector<bool> label_column;                         // per command column
  std::vector<double> pose_unit, conditioning_unit;
  std::vector<std::string> conditioning_names;            // continuous commands, then terrain
};

ColumnPlan PlanColumns(const std::string& path, const CsvTable& table, const CsvImportOptions& options) {
  ColumnPlan plan;
  std::set<std::string> used;
  plan.command = FindColumns(options.command_columns, table, &used);
  plan.pose = FindColumns(options.pose_columns, table, &used);
  plan.conditioning_names = options.continuous_command_columns;
  plan.conditioning_names.insert(plan.conditioning_names.end(), options.terrain_columns.begin(),
                                 options.terrain_columns.end());
  plan.conditioning = FindColumns(plan.conditioning_names, table, &used);
  if (!options.episode_column.empty()) plan.episode = FindColumns({options.episode_column}, table, &used);
  for (const auto& [column, factor] : options.units) {
    if (!used.count(column)) {
      throw MakeInputError(path, "--units", "column '" + column + "' is not a selected column");
    }
  }
  auto unit = [&](int col) {
    auto it = options.units.find(table.header[col]);
    return it == options.units.end() ? 1.0 : it->second;
  };
  for (int col : plan.command) plan.label_column.push_back(!table.IsNumericColumn(col));
  for (int col : plan.pose) plan.pose_unit.push_back(unit(col));
  for (int col : plan.conditioning) plan.conditioning_unit.push_back(unit(col));
  return plan;
}

// One data row: its command key (numbers, or label codes), label, x, z and episode id.
struct ParsedRow {
  std::vector<double> key, x, z;
  std::string label;
  int episode = 0;
};

std::string Where(const CsvTable& table, const CsvRecord& record, const std::string& column) {
  return "line " + std::to_string(record.line) + ", column '" + column + "'";
}

int EpisodeId(const std::string& path, const CsvTable& table, const CsvRecord& record, int col) {
  const double e = table.Number(record, col);
  if (e != std::floor(e) || std::abs(e) > 2e9) {
    char shown[32];
    std::snprintf(shown, sizeof shown, "%.6g", e);
    throw MakeInputError(path, Where(table, record, EchoCell(table.header[col])),
                         std::string("episode id ") + shown + ", expected an integer between -2e9 and 2e9");
  }
  return static_cast<int>(e);
}

// InputError naming the line and column for a bad field; label codes are assigned in row order.
ParsedRow ParseRow(const std::string& path, const CsvTable& table, const CsvRecord& record, const ColumnPlan& plan,
                   std::vector<std::map<std::string, int>>* label_codes) {
  table.CheckFieldCount(record);
  ParsedRow row;
  for (size_t c = 0; c < plan.command.size(); ++c) {
    const int col = plan.command[c];
    const std::string& cell = record.fields[col];
    if (plan.label_column[c]) {
      if (cell.empty()) throw MakeInputError(path, Where(table, record, table.header[col]), "empty command label");
      auto [it, fresh] = (*label_codes)[c].try_emplace(cell, static_cast<int>((*label_codes)[c].size()));
      row.key.push_back(it->second);
    } else {
      row.key.push_back(table.Number(record, col));
    }
    row.label += (row.label.empty() ? "" : ",") + cell;
  }
  for (size_t j = 0; j < plan.pose.size(); ++j) row.x.push_back(table.Number(record, plan.pose[j]) * plan.pose_unit[j]);
  for (size_t j = 0; j < plan.conditioning.size(); ++j) {
    row.z.push_back(table.Number(record, plan.conditioning[j]) * plan.conditioning_unit[j]);
  }
  if (!plan.episode.empty()) row.episode = EpisodeId(path, table, record, plan.episode[0]);
  return row;
}

// The rows kept so far; commands numbered in order of first appearance, steps per episode.
struct KeptRows {
  std::vector<double> xs, zs;
  std::vector<int> commands, episodes, steps;
  std::map<std::vector<double>, int> command_ids;
  std::vector<std::vector<double>> command_rows;
  std::vector<std::string> labels;
  std::map<int, int> steps_so_far;

  void Add(const ParsedRow& row, bool named_commands, bool with_episodes) {
    auto [it, inserted] = command_ids.try_emplace(row.key, static_cast<int>(command_rows.size()));
    if (inserted) {
      command_rows.push_back(row.key);
      labels.push_back(named_commands ? row.label : "all");
    }
    commands.push_back(it->second);
    xs.insert(xs.end(), row.x.begin(), row.x.end());
    zs.insert(zs.end(), row.z.begin(), row.z.end());
    if (with_episodes) {
      episodes.push_back(row.episode);
      steps.push_back(steps_so_far[row.episode]++);
    }
  }
};

SampleSet AssembleSet(KeptRows& kept, const ColumnPlan& plan, const CsvImportOptions& options) {
  const long long n = static_cast<long long>(kept.commands.size());
  const int dx = static_cast<int>(plan.pose.size()), dz = static_cast<int>(plan.conditioning.size());
  SampleSet set;
  set.command_dim_names = options.command_columns;
  set.commands.resize(static_cast<Eigen::Index>(kept.command_rows.size()), static_cast<Eigen::Index>(plan.command.size()));
  for (size_t r = 0; r < kept.command_rows.size(); ++r) {
    for (size_t c = 0; c < plan.command.size(); ++c) set.commands(r, c) = kept.command_rows[r][c];
  }
  set.command_labels = kept.labels;
  set.command = Eigen::Map<Eigen::VectorXi>(kept.commands.data(), n);
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  set.x = Eigen::Map<RowMatrix>(kept.xs.data(), n, dx);
  set.x_names = options.pose_columns;
  if (dz > 0) {
    set.z = Eigen::Map<RowMatrix>(kept.zs.data(), n, dz);
    set.z_names = plan.conditioning_names;
  }
  if (!options.continuous_command_columns.empty()) {
    set.metadata["continuous_command_columns"] = std::to_string(options.continuous_command_columns.size());
  }
  if (!kept.episodes.empty()) {
    set.episode = Eigen::Map<Eigen::VectorXi>(kept.episodes.data(), n);
    set.step = Eigen::Map<Eigen::VectorXi>(kept.steps.data(), n);
  }
  return set;
}

}  // namespace

// Stages: choose the columns, parse the rows (dropping or refusing bad ones), assemble the set.
SampleSet ImportCsv(const std::string& path, const CsvImportOptions& options, CsvImportSummary* summary) {
  if (options.pose_columns.empty()) {
    throw MakeInputError(path, "pose columns", "none chosen (expected at least one)");
  }
  const CsvTable table = ReadCsv(path, options.delimiter);
  const ColumnPlan plan = PlanColumns(path, table, options);
  std::vector<std::map<std::string, int>> label_codes(plan.command.size());
  KeptRows kept;
  InvalidRows invalid(options.drop_invalid);
  for (const CsvRecord& record : table.records) {
    try {
      kept.Add(ParseRow(path, table, record, plan, &label_codes), !plan.command.empty(), !plan.episode.empty());
    } catch (const InputError& e) {
      invalid.Handle(path, e.what());
    }
  }
  if (summary) {
    summary->dropped_rows = invalid.total();
    summary->dropped_report = invalid.Report();
  }
  if (kept.commands.empty()) {
    throw MakeInputError(path, "", invalid.total() > 0 ? "every data row was invalid and dropped"
                                                     : "no data rows after the header");
  }
  SampleSet set = AssembleSet(kept, plan, options);
  set.source = options.source;
  set.metadata["imported_from"] = std::filesystem::path(path).filename().string();
  if (options.standardize) set.transform = Standardize(&set.x, &set.z);
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(path, "", e);
  return set;
}

}  // namespace dgmm
