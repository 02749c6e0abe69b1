#pragma once
// The flags that cv and tune share: the set, how it is split into folds, the repeats, seed and
// threads, the pose and terrain dimensions, and JSON output. Each command's arguments extend
// CvFlags with their own; --with-terrain/--without-terrain mean different things to the two
// commands (rows shown, likelihood maximised) and stay with each.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "tune/cross_validation.h"

namespace dgmm::app {

struct CvFlags {
  std::string path;
  int folds = 0;  // 0: chosen from the data (unless --folds was given)
  bool folds_given = false;
  int repeats = 10;
  std::uint64_t seed = 1;
  int threads = 0;
  bool shuffle_training = false;
  bool stratified = false;
  bool with_terrain = false, without_terrain = false;
  std::vector<std::string> pose_dims, terrain_dims;
  bool json = false;
};

// Adds the set, --folds, --repeats, --seed, --threads, --shuffle-training, --stratified,
// --pose-dims, --terrain-dims and --json to cmd.
void AddCvFlags(CLI::App* cmd, CvFlags* flags);

// In cmd's callback, before the run: whether --folds was given.
void NoteFoldsGiven(const CLI::App& cmd, CvFlags* flags);

// The set to cross-validate with its chosen dimensions, after checking --folds (>= 2 when given)
// and --repeats (>= 1): InputError naming the flag.
SampleSet ReadCvSet(const CvFlags& flags);

// The folds (checked against the set), grouping, repeats, seed, threads and training order of the
// flags, written into `cv`; the DGMM options and the rest are the caller's.
void SetCvOptions(const CvFlags& flags, const SampleSet& set, CvOptions* cv);

}  // namespace dgmm::app
