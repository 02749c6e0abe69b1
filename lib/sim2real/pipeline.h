#pragma once
// dgmm sim2real end to end: locate where the sim-trained model fails on real data, name the
// physics the simulation left out (effect library, sparse selection by held-out likelihood,
// bootstrap), and measure how much of the gap the corrected model closes. See docs/sim2real.md.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/effect_fit.h"
#include "sim2real/effects.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/locate.h"
#include "sim2real/selection.h"

namespace dgmm::sim2real {

struct Sim2RealOptions {
  std::uint64_t seed = 1;
  int terrain_regions = 3;   // k of the k-means clusters of z
  int sim_residual_folds = 5;
  LinearGaussianOptions model;
  SelectionOptions selection;
  LocateOptions locate;
  // Restricts the data-level effect library to these keys (empty: all usable ones). An unknown
  // key is an InputError naming the valid ones.
  std::vector<std::string> only_effects;
  bool IsValid(std::string* error) const;
};

struct EffectReport {
  EffectSpec spec;
  Eigen::VectorXd theta, lower, upper;  // estimate and 95% bootstrap interval per parameter
  double inclusion = 0;                 // bootstrap inclusion probability
  double gain = 0, gain_se = 0;         // held-out nats per real sample when it was added
  double importance = 0;                // held-out nats per real sample lost without it (rank key)
  int selection_step = 0;               // 1-based forward step that added it
  std::vector<std::string> confusable_with;  // keys of effects the data cannot tell apart from it
  std::string sentence;
};

struct Sim2RealResult {
  // Inputs, as understood.
  int n_real = 0, n_sim = 0, pose_dim = 0, terrain_dim = 0;
  bool has_sequence = false;
  PoseLayout layout;
  std::vector<std::string> command_labels;   // shared ids = sim command rows
  std::vector<int> real_commands;            // shared ids present in the real set
  Eigen::MatrixXd terrain_centres;           // k x dz
  std::vector<std::string> terrain_labels;
  double slope_sin = 0;                      // median |g_h| of the real samples
  // 1. Locate: before and after the correction.
  std::vector<Region> before, after;
  int pooled_x_flagged = 0, conditional_flagged = 0;  // significant regions per approach
  bool significant_mismatch = false;
  Eigen::MatrixXd heat_before, heat_after;   // deficit per (command row in real_commands) x terrain
  // 2. Effects: selected, ranked by importance, and the candidate table of every forward step.
  std::vector<EffectReport> effects;
  std::vector<SelectionStep> steps;
  std::vector<double> inclusion;             // per library effect
  std::vector<EffectSpec> library;
  std::vector<Region> unexplained;           // significant after the correction
  // 4. Held-out real log-likelihood per sample.
  double ll_sim = 0, ll_corrected = 0, ll_ceiling = 0;
  double ll_real_only = 0;         // real-trained without the sim prior
  double ceiling_prior_count = 0;  // strength of the sim prior in the best real-trained model
  double gap_closed = 0;                     // (corrected - sim) / (ceiling - sim); NaN if no gap
  std::string conclusion;                    // one paragraph
  // For the model export.
  LinearGaussianModel sim_model;
  EffectFit fit;
  double first_execution_share = 0;          // of the real samples
  double seconds = 0;
  int bootstrap_resamples = 0;               // 0: inclusion probabilities not computed
  // Real commands (labels) with no sim counterpart, dropped from the analysis.
  std::vector<std::string> dropped_commands;
  int dropped_samples = 0;
};

// Throws InputError when the sets cannot be compared (dimensions, no shared commands, too few
// samples).
Sim2RealResult RunSim2Real(const SampleSet& sim, const SampleSet& real, const Sim2RealOptions& options);

}  // namespace dgmm::sim2real
