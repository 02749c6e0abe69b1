#pragma once
// What a 2-D picture of a motion model shows: p(u, v | c) over two named dimensions of
// y = x || z, with the others either marginalised or conditioned on given values (eq. 15),
// always in raw units (the model's standardisation y_raw = offset + scale .* y_std undone).
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "core/mixture.h"
#include "core/motion_model.h"
#include "core/sample_set.h"

namespace dgmm {

struct SliceSpec {
  std::string command;         // command id or label; empty: the model's only command
  std::string x_dim, y_dim;    // dimension names; empty: the first two dimensions
  std::vector<std::pair<std::string, double>> conditions;  // name = value in raw units
  bool marginalise = false;    // required when d > 2 and some dimension is neither shown nor given
};

struct ModelSlice {
  Mixture mixture;              // 2-D over (x_dim, y_dim), raw units
  int command = 0;
  int x_index = 0, y_index = 0;  // indices into y = x || z
  std::string x_label, y_label;  // "name (unit)"
  std::string description;       // e.g. "p(eruptions, waiting | command 0)"
};

// Names of y = x || z: pose names then terrain names.
std::vector<std::string> DimensionNames(const MotionModel& model);

// Command id for a SliceSpec::command string (id or label). Throws InputError naming `file`.
int ResolveCommand(const MotionModel& model, const std::string& command, const std::string& file);

// The command's mixture in raw units (all dimensions of y).
Mixture RawMixture(const MotionModel& model, int command);

// Throws InputError (naming `file`) for unknown names, a dimension used twice, d < 2, or
// leftover dimensions without `marginalise`.
ModelSlice SliceModel(const MotionModel& model, const SliceSpec& spec, const std::string& file);

// y = x || z in raw units for every sample of the set with that command (the set's own
// standardisation undone); rows = samples, columns = dimensions of y.
Eigen::MatrixXd RawSamples(const SampleSet& set, int command);

// (y[x_index], y[y_index]) in raw units for every sample of the set with that command
// (the set's own standardisation undone); rows = samples.
Eigen::MatrixX2d SlicePoints(const SampleSet& set, int command, int x_index, int y_index);

}  // namespace dgmm
