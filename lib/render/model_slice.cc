#include "render/model_slice.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "util/error.h"

namespace dgmm {
namespace {

int FindDimension(const std::vector<std::string>& names, const std::string& name,
                  const std::string& file) {
  auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ",") + n;
    throw MakeInputError(file, "dimension", "unknown name '" + name + "' (known: " + known + ")");
  }
  return static_cast<int>(it - names.begin());
}

std::string Label(const MotionModel& model, int index, const std::string& name) {
  std::string unit;
  if (index < model.pose_dim && index < static_cast<int>(model.pose_units.size())) {
    unit = model.pose_units[index];
  }
  // Terrain angles are radians by dgmm's convention (docs/file-format.md); other dimensions
  // without a recorded unit say so rather than leave the reader guessing.
  if (unit.empty() && index >= model.pose_dim && (name == "pitch" || name == "roll")) unit = "rad";
  if (unit.empty()) return name + " (no unit recorded)";
  return name + " (" + unit + ")";
}

std::string FormatValue(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", v);
  return buffer;
}

}  // namespace

std::vector<std::string> DimensionNames(const MotionModel& model) {
  std::vector<std::string> names;
  for (int i = 0; i < model.pose_dim; ++i) {
    names.push_back(i < static_cast<int>(model.pose_names.size()) ? model.pose_names[i]
                                                                  : "x" + std::to_string(i));
  }
  for (int i = 0; i < model.terrain_dim; ++i) {
    names.push_back(i < static_cast<int>(model.terrain_names.size()) ? model.terrain_names[i]
                                                                     : "z" + std::to_string(i));
  }
  return names;
}

int ResolveCommand(const MotionModel& model, const std::string& command, const std::string& file) {
  if (model.mixtures.empty()) throw MakeInputError(file, "commands", "the model has no commands");
  if (command.empty()) {
    if (model.mixtures.size() == 1) return model.mixtures.begin()->first;
    throw MakeInputError(file, "commands",
                         "the model has " + std::to_string(model.mixtures.size()) +
                             " commands; choose one with --command");
  }
  for (const auto& [id, label] : model.command_labels) {
    if (label == command && model.HasCommand(id)) return id;
  }
  try {
    size_t used = 0;
    int id = std::stoi(command, &used);
    if (used == command.size() && model.HasCommand(id)) return id;
  } catch (const std::exception&) {
  }
  throw MakeInputError(file, "command", "unknown command '" + command + "'");
}

Mixture RawMixture(const MotionModel& model, int command) {
  const Mixture& mixture = model.MixtureFor(command);
  if (model.transform.empty()) return mixture;
  const Eigen::VectorXd& scale = model.transform.scale;
  return mixture.Affine(scale.asDiagonal().toDenseMatrix(), model.transform.offset);
}

ModelSlice SliceModel(const MotionModel& model, const SliceSpec& spec, const std::string& file) {
  const std::vector<std::string> names = DimensionNames(model);
  const int d = static_cast<int>(names.size());
  if (d < 2) throw MakeInputError(file, "dimensions", "a 2-D picture needs at least 2 dimensions");
  ModelSlice slice;
  slice.command = ResolveCommand(model, spec.command, file);
  slice.x_index = spec.x_dim.empty() ? 0 : FindDimension(names, spec.x_dim, file);
  slice.y_index = spec.y_dim.empty() ? (slice.x_index == 0 ? 1 : 0)
                                     : FindDimension(names, spec.y_dim, file);
  if (slice.x_index == slice.y_index) {
    throw MakeInputError(file, "dimension", "x and y must be different dimensions");
  }
  std::set<int> used{slice.x_index, slice.y_index};
  std::vector<int> given;
  Eigen::VectorXd values(static_cast<Eigen::Index>(spec.conditions.size()));
  std::string condition_text;
  for (const auto& [name, value] : spec.conditions) {
    int index = FindDimension(names, name, file);
    if (!used.insert(index).second) {
      throw MakeInputError(file, "condition", "dimension '" + name + "' is used twice");
    }
    if (!std::isfinite(value)) {
      throw MakeInputError(file, "condition", "value of '" + name + "' is not finite");
    }
    values(static_cast<Eigen::Index>(given.size())) = value;
    given.push_back(index);
    condition_text += ", " + name + "=" + FormatValue(value);
  }
  std::string leftover;
  for (int i = 0; i < d; ++i) {
    if (!used.count(i)) leftover += (leftover.empty() ? "" : ",") + names[i];
  }
  if (!leftover.empty() && !spec.marginalise) {
    throw MakeInputError(file, "dimensions",
                         "dimensions " + leftover +
                             " are neither shown nor conditioned; pass --marginalise or "
                             "--condition name=value");
  }
  // Marginalise first (exact), keeping [x, y, given...]; then condition on the given values.
  std::vector<int> keep{slice.x_index, slice.y_index};
  keep.insert(keep.end(), given.begin(), given.end());
  Mixture kept = RawMixture(model, slice.command).Marginal(keep);
  if (!given.empty()) {
    std::vector<int> given_local;
    for (size_t g = 0; g < given.size(); ++g) given_local.push_back(2 + static_cast<int>(g));
    // p(given values) must be a number: a value whose distance from every component overflows
    // (e.g. pitch=1e308) has no conditional, even when one component's weight renormalises to 1.
    const bool reachable = std::isfinite(kept.Marginal(given_local).LogDensity(values));
    kept = kept.Conditional(given_local, values);
    bool usable = reachable && !kept.empty() && std::isfinite(kept.total_weight()) &&
                  kept.total_weight() > 0;
    for (int i = 0; usable && i < kept.size(); ++i) {
      usable = std::isfinite(kept.weight(i)) && kept.component(i).mean().allFinite();
    }
    if (!usable) {
      throw MakeInputError(file, "condition",
                           "values" + condition_text.substr(1) +
                               " are so far from every component that the conditional density "
                               "is not a number; expected values near the data");
    }
  }
  slice.mixture = kept;
  slice.x_label = Label(model, slice.x_index, names[slice.x_index]);
  slice.y_label = Label(model, slice.y_index, names[slice.y_index]);
  std::string command_text = "command " + std::to_string(slice.command);
  if (auto it = model.command_labels.find(slice.command);
      it != model.command_labels.end() && !it->second.empty()) {
    command_text = "command " + it->second;
  }
  slice.description = "p(" + names[slice.x_index] + ", " + names[slice.y_index] + " | " +
                      command_text + condition_text + ")";
  if (!leftover.empty()) slice.description += ", marginal over " + leftover;
  return slice;
}

Eigen::MatrixXd RawSamples(const SampleSet& set, int command) {
  std::vector<int> rows;
  for (int i = 0; i < set.size(); ++i) {
    if (set.command(i) == command) rows.push_back(i);
  }
  const int d = static_cast<int>(set.pose_dim() + set.terrain_dim());
  Eigen::MatrixXd samples(static_cast<Eigen::Index>(rows.size()), d);
  for (size_t r = 0; r < rows.size(); ++r) {
    Eigen::VectorXd y = set.Joint(rows[r]);
    if (!set.transform.empty()) {
      y = set.transform.offset.array() + set.transform.scale.array() * y.array();
    }
    samples.row(static_cast<Eigen::Index>(r)) = y.transpose();
  }
  return samples;
}

Eigen::MatrixX2d SlicePoints(const SampleSet& set, int command, int x_index, int y_index) {
  const int d = static_cast<int>(set.pose_dim() + set.terrain_dim());
  if (x_index >= d || y_index >= d) {
    throw MakeInputError("", "data", "the sample set has only " + std::to_string(d) +
                                         " dimensions");
  }
  const Eigen::MatrixXd samples = RawSamples(set, command);
  Eigen::MatrixX2d points(samples.rows(), 2);
  points.col(0) = samples.col(x_index);
  points.col(1) = samples.col(y_index);
  return points;
}

}  // namespace dgmm
