#pragma once
// Locating the mismatch: terrain regions (k-means clusters of z), sequence regions (first
// execution after a change of command or a repeat), commands, and command x terrain cells. For
// each: the held-out log-likelihood deficit per real sample (real-trained ceiling minus the model
// under test) and a kernel two-sample test (MMD, permutations) between the real samples' whitened
// residuals under the model and the sim samples' cross-fitted residuals, with Benjamini-Hochberg
// control within each family. Also the naive test: per command, real x vs sim x pooled over
// terrain and sequence.
#include <Eigen/Dense>
#include <random>
#include <string>
#include <vector>

#include "sim2real/samples.h"
#include "sim2real/two_sample.h"

namespace dgmm::sim2real {

// k-means (k-means++ seeding, Lloyd iterations) of the rows of z; returns the centres (k x dz)
// sorted by their first column, and fills the label of each row of `z`.
Eigen::MatrixXd TerrainClusters(const Eigen::MatrixXd& z, int k, std::mt19937_64& rng);
// Index of the nearest centre of each row of z.
std::vector<int> NearestCentre(const Eigen::MatrixXd& z, const Eigen::MatrixXd& centres);
// "facing downhill (pitch +17.8 deg, roll -0.3 deg)" from a centre <pitch, roll> in rad.
std::string DescribeTerrain(const Eigen::VectorXd& centre, int pitch_col, int roll_col);

struct Region {
  std::string family;  // "terrain", "sequence", "command", "cell", "pooled_x"
  std::string label;
  int command = -1, terrain = -1, sequence = -1;  // -1: all
  int n_real = 0, n_sim = 0;
  double deficit = 0;        // nats per real sample: ceiling minus model, held out
  double mmd2 = 0, p_value = 1, q_value = 1;
  bool significant = false;  // q < alpha
};

struct LocateInput {
  const Samples* real = nullptr;
  const Samples* sim = nullptr;
  Eigen::MatrixXd real_residuals;   // whitened under the model being examined
  Eigen::MatrixXd sim_residuals;    // whitened, cross-fitted sim residuals under the sim model
  Eigen::VectorXd model_heldout;    // per real sample
  Eigen::VectorXd ceiling_heldout;  // per real sample
  std::vector<int> real_terrain, sim_terrain;  // region id per sample
  std::vector<std::string> terrain_labels;
  std::vector<std::string> command_labels;     // by shared command id
  bool with_cells = true;
  bool with_pooled_x = true;
};

struct LocateOptions {
  MmdOptions mmd;
  double alpha = 0.05;
  int min_real_per_cell = 3;
  // Permute whole placements (Samples::episode) instead of samples: the executions at one
  // placement share its ground and are not exchangeable one by one on rough ground.
  bool permute_placements = false;
  bool IsValid(std::string* error) const;
};

// All regions of all families, BH-controlled, sorted: significant first, then by
// deficit (largest first).
std::vector<Region> Locate(const LocateInput& in, const LocateOptions& options, std::mt19937_64& rng);

}  // namespace dgmm::sim2real
