#pragma once
// The per-sample view the sim-vs-real analysis works on: command, pose change x, terrain z and the
// sequence context.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm::sim2real {

// Which entries of x carry the planar motion and the attitude changes (-1 when absent). Taken
// from x_names (dx, dy, dz, droll, dpitch, dyaw and common spellings), else from the documented
// order <dx, dy, dz, droll, dpitch, dyaw> when x has 6 columns.
struct PoseLayout {
  int dx = -1, dy = -1, dz = -1, droll = -1, dpitch = -1, dyaw = -1;
  bool has_planar() const { return dx >= 0 && dy >= 0; }
};
PoseLayout DetectPoseLayout(const SampleSet& set);

// Samples of one set, flattened. Rows of x/z are samples.
struct Samples {
  std::vector<int> command;        // index into the shared command table (see AlignCommands)
  Eigen::MatrixXd x;               // n x dx
  Eigen::MatrixXd z;               // n x dz (dz may be 0)
  std::vector<int> episode;        // placement id (one per sample; 0..n-1 without sequence data)
  // 1 for the first execution after a change of command (step 0 of a placement), else 0.
  std::vector<int> first_execution;
  bool has_sequence = false;
  int size() const { return static_cast<int>(x.rows()); }
  int pose_dim() const { return static_cast<int>(x.cols()); }
  int terrain_dim() const { return static_cast<int>(z.cols()); }
};


// Index of the pitch and roll columns of z (by name, else columns 0 and 1), -1 when absent.
void DetectTerrainColumns(const SampleSet& set, int* pitch, int* roll);

// Flattens `set`; command ids are mapped through `command_map` (set row -> shared id, -1 drops
// the sample).
Samples MakeSamples(const SampleSet& set, const std::vector<int>& command_map);
// Every sample, command ids as in `set` (the identity map).
Samples MakeSamples(const SampleSet& set);

// Maps the real set's command rows onto the sim set's (by label, then by command values).
// Returns, per real row, the sim row or -1. Throws InputError when x or z dimensions differ.
std::vector<int> AlignCommands(const SampleSet& sim, const SampleSet& real);

// The set in raw units: x || z = offset + scale .* y_std when it carries a standardisation
// transform (SampleSet::transform), else unchanged. Throws InputError "<which>: transform: ..."
// when the transform does not match the dimensions or has non-finite or non-positive scales.
SampleSet ToRawUnits(const SampleSet& set, const std::string& which);

// Rows of `s` listed in `rows`, in that order.
Samples SubsetSamples(const Samples& s, const std::vector<int>& rows);

}  // namespace dgmm::sim2real
