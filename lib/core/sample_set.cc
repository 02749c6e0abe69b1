#include "core/sample_set.h"

#include <cassert>
#include <cmath>
#include <string>

namespace dgmm {
namespace {

std::string Str(long long v) { return std::to_string(v); }

// "row r, column c" of the first non-finite entry of m, or empty.
std::string FirstNonFinite(const Eigen::MatrixXd& m, const std::vector<std::string>& names) {
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      if (!std::isfinite(m(r, c))) {
        const std::string column =
            c < static_cast<Eigen::Index>(names.size()) ? " ('" + names[c] + "')" : "";
        return "row " + Str(r) + ", column " + Str(c) + column + " is " +
               (std::isnan(m(r, c)) ? "NaN" : "infinite") + ", expected a finite number";
      }
    }
  }
  return "";
}

// Empty if `names` is empty or has `expected` entries.
std::string CheckNames(const char* field, const std::vector<std::string>& names,
                       long long expected) {
  if (names.empty() || static_cast<long long>(names.size()) == expected) return "";
  return std::string(field) + ": " + Str(names.size()) + " names for " + Str(expected) + " columns";
}

}  // namespace

Eigen::VectorXd SampleSet::Joint(int i) const {
  Eigen::VectorXd y(pose_dim() + terrain_dim());
  y.head(pose_dim()) = x.row(i).transpose();
  if (terrain_dim() > 0) y.tail(terrain_dim()) = z.row(i).transpose();
  return y;
}

std::string SampleSet::Validate() const {
  const long long n = x.rows();
  if (n == 0) return "x: no samples (expected at least one row)";
  if (x.cols() == 0) return "x: no pose dimensions (expected at least one column)";
  for (const std::string& e :
       {CheckNames("x names", x_names, x.cols()), CheckNames("x units", x_units, x.cols())}) {
    if (!e.empty()) return e;
  }
  if (z.cols() > 0 && z.rows() != n) {
    return "z: " + Str(z.rows()) + " rows, expected one per sample (" + Str(n) + ")";
  }
  for (const std::string& e :
       {CheckNames("z names", z_names, z.cols()), CheckNames("z units", z_units, z.cols())}) {
    if (!e.empty()) return e;
  }
  if (commands.rows() == 0) return "commands: the command table is empty (expected >= 1 row)";
  if (std::string e = CheckNames("command names", command_dim_names, commands.cols()); !e.empty()) {
    return e;
  }
  if (!command_labels.empty() && static_cast<long long>(command_labels.size()) != commands.rows()) {
    return "command labels: " + Str(command_labels.size()) + " labels for " + Str(commands.rows()) +
           " commands";
  }
  if (command.size() != n) {
    return "command: " + Str(command.size()) + " entries, expected one per sample (" + Str(n) + ")";
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (command[i] < 0 || command[i] >= commands.rows()) {
      return "command: sample " + Str(i) + " has command index " + Str(command[i]) +
             ", expected 0.." + Str(commands.rows() - 1);
    }
  }
  if (std::string e = FirstNonFinite(x, x_names); !e.empty()) return "x: " + e;
  if (std::string e = FirstNonFinite(z, z_names); !e.empty()) return "z: " + e;
  if (std::string e = FirstNonFinite(commands, command_dim_names); !e.empty()) {
    return "commands: " + e;
  }
  if (episode.size() != step.size()) {
    return "episode/step: " + Str(episode.size()) + " episode ids but " + Str(step.size()) +
           " step indices (expected both empty or both one per sample)";
  }
  if (episode.size() != 0 && episode.size() != n) {
    return "episode: " + Str(episode.size()) + " entries, expected one per sample (" + Str(n) + ")";
  }
  if (!transform.empty()) {
    const long long dy = x.cols() + z.cols();
    if (transform.offset.size() != dy || transform.scale.size() != dy) {
      return "transform: offset/scale have " + Str(transform.offset.size()) + "/" +
             Str(transform.scale.size()) + " entries, expected " + Str(dy) + " (x and z)";
    }
    if (!transform.offset.allFinite() || !transform.scale.allFinite() ||
        (transform.scale.array() <= 0).any()) {
      return "transform: offsets must be finite and scales finite and > 0";
    }
  }
  return "";
}

SampleSet SampleSet::Subset(const std::vector<int>& rows) const {
  SampleSet out;
  out.command_dim_names = command_dim_names;
  out.commands = commands;
  out.command_labels = command_labels;
  out.x_names = x_names;
  out.x_units = x_units;
  out.z_names = z_names;
  out.z_units = z_units;
  out.source = source;
  out.metadata = metadata;
  out.transform = transform;
  const int m = static_cast<int>(rows.size());
  out.command.resize(m);
  out.x.resize(m, x.cols());
  out.z.resize(z.cols() > 0 ? m : 0, z.cols());
  if (has_sequence()) {
    out.episode.resize(m);
    out.step.resize(m);
  }
  for (int j = 0; j < m; ++j) {
    const int r = rows[j];
    assert(r >= 0 && r < size());
    out.command[j] = command[r];
    out.x.row(j) = x.row(r);
    if (z.cols() > 0) out.z.row(j) = z.row(r);
    if (has_sequence()) {
      out.episode[j] = episode[r];
      out.step[j] = step[r];
    }
  }
  return out;
}

}  // namespace dgmm
