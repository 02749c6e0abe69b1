#pragma once
// Stage 2 of the analysis (analysis.h), "locate": the sim-trained reference model, the real
// folds every held-out comparison shares, the real-trained ceiling, the terrain regions, and where
// the sim model fails on the real samples (locate.h: terrain, sequence, command and cell regions,
// Benjamini-Hochberg controlled). Needs no simulator: without one the analysis stops here.
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "sim2real/ceiling.h"
#include "sim2real/inputs.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/locate.h"
#include "sim2real/placement_dependence.h"

namespace dgmm::sim2real {

struct BaselineOptions {
  std::uint64_t seed = 1;
  int folds = 5;               // grouped by episode (selection.h, MakeFolds)
  int terrain_regions = 3;     // k of the k-means clusters of z
  int sim_residual_folds = 5;
  LinearGaussianOptions model;
  LocateOptions locate;
  PlacementDependenceOptions placement;  // seeded with `seed`
  // The simulator's ground is a height field: where a placement stands shapes all its executions
  // and z does not say where, so locate permutes whole placements whatever the test says.
  bool uneven_ground = false;
  bool IsValid(std::string* error) const;
};

// Where a model fails on the real samples: regions, the command x terrain heat map, counts.
struct LocateSummary {
  std::vector<Region> regions;        // every family, significant first
  Eigen::MatrixXd heat;               // deficit per (real_commands row) x terrain region
  int pooled_x_flagged = 0;           // significant per-command tests of x alone
  int conditional_flagged = 0;        // significant terrain, sequence and command regions
  std::vector<Region> significant;    // those conditional regions
};

struct Baseline {
  LinearGaussianModel sim_model;
  std::vector<int> fold;              // per real sample
  Eigen::VectorXd heldout_sim;        // per real sample: the sim model (no fitting involved)
  Eigen::VectorXd heldout_ceiling;    // per real sample: the best real-trained model, same folds
  double ll_sim = 0, ll_ceiling = 0, ll_real_only = 0, ceiling_prior_count = 0;
  Eigen::MatrixXd terrain_centres;    // k x dz
  std::vector<std::string> terrain_labels;
  std::vector<int> real_terrain, sim_terrain;  // region per sample
  Eigen::MatrixXd sim_residuals;      // cross-fitted whitened sim residuals (the null of the tests)
  Eigen::MatrixXd sim_own_residuals;  // whitened sim residuals under the sim model fitted on them all
  Eigen::MatrixXd real_residuals;     // whitened real residuals under the sim model
  // Are the executions at a placement dependent? When they are, or the ground is uneven, every
  // locate permutes whole placements (LocateOptions::permute_placements), for the reason in words.
  PlacementDependence placement;
  bool permute_placements = false;
  std::string permute_why;
  LocateSummary before;
  bool significant_mismatch = false;  // a terrain, sequence or command region is significant
};

Baseline LocateMismatch(const AnalysisInputs& in, const BaselineOptions& options);

// Locate for another model of the real samples: its whitened residuals (n x dx) and held-out
// log-likelihoods (n), against the baseline's sim residuals and ceiling. `rng` seeds the tests;
// placements are permuted whole when `options` or the baseline's placement test says so.
LocateSummary LocateModel(const AnalysisInputs& in, const Baseline& base, const Eigen::MatrixXd& real_residuals,
                          const Eigen::VectorXd& heldout, bool with_pooled_x, const LocateOptions& options,
                          std::mt19937_64& rng);

}  // namespace dgmm::sim2real
