#pragma once
// Stage 1 of the analysis (analysis.h): the two sets as the analysis sees them. Both in raw units,
// the real samples' commands mapped onto the sim set's table (real commands the sim set lacks are
// dropped and listed), the pose layout, and the sim set's own recording (protocol and seed from
// its metadata, which `dgmm simulate` writes) for re-recordings at other knob values.
#include <cstdint>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/knob_simulator.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct AnalysisInputs {
  SampleSet sim_set, real_set;               // raw units
  Samples sim, real;                         // real: only commands the sim set has
  std::vector<int> real_source_row;          // per real sample: its row in real_set
  PoseLayout layout;
  std::vector<std::string> command_labels;   // per sim command row
  std::vector<int> real_commands;            // sim rows present in the real set, ascending
  std::vector<std::string> dropped_commands; // real command labels with no sim counterpart
  int dropped_samples = 0;
  double first_execution_share = 0;          // of the real samples
  Recording recording;                       // the sim set's own
  bool recording_from_metadata = false;      // false: protocol "paper", seed = fallback
  int pitch_col = -1, roll_col = -1;         // terrain columns (-1: absent)
};

// Throws InputError naming --sim or --real when a set is invalid, dimensions differ, or fewer
// than 10 real samples share a command with the sim set.
AnalysisInputs PrepareInputs(const SampleSet& sim, const SampleSet& real, std::uint64_t fallback_seed);

// Placements (episodes) per command, the median over the real set's commands, of each set.
struct PlacementsPerCommand {
  double sim = 0, real = 0;
};
PlacementsPerCommand CountPlacementsPerCommand(const AnalysisInputs& in);

// A warning when the sim set has no more placements per command than the real set (else ""). The
// sim residuals that locate compares with the real ones are cross-fitted with whole placements
// held out: with one sim placement per setting (the paper protocol's headings, shared by both
// sets) a held-out sim sample meets a setting its model never saw, while every real sample's is
// in the sim model, and locate then finds mismatch in pairs of the same robot (docs/sim2real.md).
std::string SmallSimSetNote(const AnalysisInputs& in, const std::string& sim_path);

}  // namespace dgmm::sim2real
