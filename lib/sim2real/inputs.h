#pragma once
// Stage 1 of the analysis (analysis.h): the two sets as the analysis sees them. Both in raw units,
// the real samples' commands mapped onto the sim set's table (real commands the sim set lacks are
// dropped and listed), the pose layout, and the sim set's own recording (protocol and seed from
// its metadata, which `dgmm simulate` writes) for re-recordings at other knob values.
#include <cstdint>
#include <optional>
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
  std::optional<std::uint64_t> real_seed;    // the real set's own recording seed, when its metadata has one
  int pitch_col = -1, roll_col = -1;         // terrain columns (-1: absent)
};

// Throws InputError naming --sim or --real when a set is invalid, dimensions differ, or fewer
// than 10 real samples share a command with the sim set.
AnalysisInputs PrepareInputs(const SampleSet& sim, const SampleSet& real, std::uint64_t fallback_seed);

// Per real sample (in.real's order) its execution index within its placement; all -1 without
// sequence data.
std::vector<int> RealSteps(const AnalysisInputs& in);
// The same for the sim samples (in.sim's order).
std::vector<int> SimSteps(const AnalysisInputs& in);

// The real set's placements and executions per placement (without sequence data each sample is
// its own placement, as the analysis treats it).
struct PlacementCount {
  int placements = 0, executions_per_placement = 1;
};
PlacementCount RealPlacements(const AnalysisInputs& in);

// How closely the sim set's placements cover the settings (terrain z) of each command: per
// placement its mean z; medians over the real set's commands of
//   sim_to_sim  = |z_p - nearest other sim placement of its command|  (infinite when it has none),
//   real_to_sim = |z_r - nearest sim placement of its command|.
struct SettingCoverage {
  double sim_to_sim = 0, real_to_sim = 0;
};
SettingCoverage MeasureSettingCoverage(const AnalysisInputs& in);

// A warning (else "") when a held-out sim placement is `ratio` times farther from the rest of the
// sim set than a real placement is from the sim set. The sim residuals that locate compares with
// the real ones are cross-fitted with whole placements held out: with one sim placement per
// setting (the paper protocol's 78 placements: three headings, shared by both sets) a held-out
// sim sample meets a setting its model never saw while every real sample's is in the sim model,
// and locate then finds mismatch in pairs of the same robot (docs/sim2real.md). Measured: 28 on
// such a pair; 0.8 to 1.5 with 166 placements or random headings.
std::string SmallSimSetNote(const AnalysisInputs& in, const std::string& sim_path, double ratio = 3.0);

// The warnings dgmm gave when it made a set (core/set_warnings.h: a torso that started tilted, legs
// touching each other, windows of unequal length), each as a note naming the set: what the analysis
// finds describes the robot as that set has it. None for a set without them (an older set, a CSV).
std::vector<std::string> RecordingNotes(const SampleSet& set, const std::string& path);

}  // namespace dgmm::sim2real
