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

}  // namespace

SampleSet ImportCsv(const std::string& path, const CsvImportOptions& options,
                    CsvImportSummary* summary) {
  if (options.pose_columns.empty()) {
    throw MakeInputError(path, "pose columns", "none chosen (expected at least one)");
  }
  const CsvTable table = ReadCsv(path, options.delimiter);
  std::set<std::string> used;
  const auto command_idx = FindColumns(options.command_columns, table, &used);
  const auto pose_idx = FindColumns(options.pose_columns, table, &used);
  std::vector<std::string> conditioning = options.continuous_command_columns;
  conditioning.insert(conditioning.end(), options.terrain_columns.begin(),
                      options.terrain_columns.end());
  const auto terrain_idx = FindColumns(conditioning, table, &used);
  std::vector<int> episode_idx;
  if (!options.episode_column.empty()) {
    episode_idx = FindColumns({options.episode_column}, table, &used);
  }
  for (const auto& [column, factor] : options.units) {
    if (!used.count(column)) {
      throw MakeInputError(path, "--units", "column '" + column + "' is not a selected column");
    }
  }
  auto unit = [&](int col) {
    auto it = options.units.find(table.header[col]);
    return it == options.units.end() ? 1.0 : it->second;
  };
  std::vector<bool> label_column;
  for (int col : command_idx) label_column.push_back(!table.IsNumericColumn(col));
  std::vector<std::map<std::string, int>> label_codes(command_idx.size());

  const int dx = static_cast<int>(pose_idx.size()), dz = static_cast<int>(terrain_idx.size());
  std::vector<double> xs, zs;
  std::vector<int> commands, episodes, steps;
  std::map<std::vector<double>, int> command_ids;
  std::vector<std::vector<double>> command_rows;
  std::vector<std::string> labels;
  std::map<int, int> steps_so_far;
  InvalidRows invalid(options.drop_invalid);
  for (const CsvRecord& record : table.records) {
    std::vector<double> key, x, z;
    std::string label;
    int episode = 0;
    try {
      table.CheckFieldCount(record);
      auto number = [&](int col) { return table.Number(record, col); };
      for (size_t c = 0; c < command_idx.size(); ++c) {
        const int col = command_idx[c];
        const std::string& cell = record.fields[col];
        if (label_column[c]) {
          if (cell.empty()) {
            throw MakeInputError(path, "line " + std::to_string(record.line) + ", column '" +
                                           table.header[col] + "'",
                                 "empty command label");
          }
          auto [it, fresh] = label_codes[c].try_emplace(cell, static_cast<int>(label_codes[c].size()));
          key.push_back(it->second);
        } else {
          key.push_back(number(col));
        }
        label += (label.empty() ? "" : ",") + cell;
      }
      for (int col : pose_idx) x.push_back(number(col) * unit(col));
      for (int col : terrain_idx) z.push_back(number(col) * unit(col));
      if (!episode_idx.empty()) {
        const double e = number(episode_idx[0]);
        if (e != std::floor(e) || std::abs(e) > 2e9) {
          char shown[32];
          std::snprintf(shown, sizeof shown, "%.6g", e);
          throw MakeInputError(path, "line " + std::to_string(record.line) + ", column '" +
                                         EchoCell(table.header[episode_idx[0]]) + "'",
                               std::string("episode id ") + shown +
                                   ", expected an integer between -2e9 and 2e9");
        }
        episode = static_cast<int>(e);
      }
    } catch (const InputError& e) {
      invalid.Handle(path, e.what());
      continue;
    }
    auto [it, inserted] = command_ids.try_emplace(key, static_cast<int>(command_rows.size()));
    if (inserted) {
      command_rows.push_back(key);
      labels.push_back(command_idx.empty() ? "all" : label);
    }
    commands.push_back(it->second);
    xs.insert(xs.end(), x.begin(), x.end());
    zs.insert(zs.end(), z.begin(), z.end());
    if (!episode_idx.empty()) {
      episodes.push_back(episode);
      steps.push_back(steps_so_far[episode]++);
    }
  }
  if (summary) {
    summary->dropped_rows = invalid.total();
    summary->dropped_report = invalid.Report();
  }
  const long long n = static_cast<long long>(commands.size());
  if (n == 0) {
    throw MakeInputError(path, "", invalid.total() > 0 ? "every data row was invalid and dropped"
                                                     : "no data rows after the header");
  }

  SampleSet set;
  set.command_dim_names = options.command_columns;
  set.commands.resize(static_cast<Eigen::Index>(command_rows.size()),
                      static_cast<Eigen::Index>(command_idx.size()));
  for (size_t r = 0; r < command_rows.size(); ++r) {
    for (size_t c = 0; c < command_idx.size(); ++c) set.commands(r, c) = command_rows[r][c];
  }
  set.command_labels = labels;
  set.command = Eigen::Map<Eigen::VectorXi>(commands.data(), n);
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  set.x = Eigen::Map<RowMatrix>(xs.data(), n, dx);
  set.x_names = options.pose_columns;
  if (dz > 0) {
    set.z = Eigen::Map<RowMatrix>(zs.data(), n, dz);
    set.z_names = conditioning;
  }
  if (!options.continuous_command_columns.empty()) {
    set.metadata["continuous_command_columns"] =
        std::to_string(options.continuous_command_columns.size());
  }
  if (!episodes.empty()) {
    set.episode = Eigen::Map<Eigen::VectorXi>(episodes.data(), n);
    set.step = Eigen::Map<Eigen::VectorXi>(steps.data(), n);
  }
  set.source = options.source;
  set.metadata["imported_from"] = std::filesystem::path(path).filename().string();
  if (options.standardize) set.transform = Standardize(&set.x, &set.z);
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(path, "", e);
  return set;
}

}  // namespace dgmm
