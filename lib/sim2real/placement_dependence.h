#pragma once
// Are the executions at one placement exchangeable one by one? On a plane the ground under the
// robot is the same everywhere and z says all there is to say about it; on rough ground where a
// placement stands (on a boulder, beside it) shapes all its executions, and z (pitch, roll) does
// not say where it stands. Then a two-sample test that permutes samples sees two sets of
// placements as two populations; locate must permute whole placements (locate.h).
//
// The test, per set, on whitened residuals r under the set's own fit (what z and the command
// leave): T = sum_p n_p |mean of r over placement p|^2, the between-placement spread, against T
// after shuffling samples among the placements of the same command (which keeps each command's own
// fit); one statistic summed over both sets.
#include <Eigen/Dense>
#include <cstdint>
#include <string>

#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct PlacementDependenceOptions {
  int permutations = 500;
  double alpha = 0.05;  // p below this: placements are permuted whole
  bool IsValid(std::string* error) const;
};

struct PlacementDependence {
  double statistic = 0;  // T summed over the sets
  double p_value = 1;    // (1 + #{shuffled T >= T}) / (1 + permutations)
  bool dependent = false;
};

// `sim_residuals` and `real_residuals`: whitened residuals of each set under its own fit (a model of
// the other set would leave its mismatch, which may vary with z from placement to placement), one
// row per sample. `seed` seeds the shuffles. Sets without placements (every sample its own
// episode) give p = 1.
PlacementDependence TestPlacementDependence(const Samples& sim, const Eigen::MatrixXd& sim_residuals,
                                            const Samples& real, const Eigen::MatrixXd& real_residuals,
                                            const PlacementDependenceOptions& options, std::uint64_t seed);

// Per column of `residuals` (one row per sample), the share of its variance the executions of one
// placement (`episode`) share: the one-way intraclass correlation
//   rho = (MSB - MSW) / (MSB + (n0 - 1) MSW),  n0 = (N - sum n_p^2 / N) / (P - 1),
// clamped to [0, 0.95]; zeros when there are fewer than two placements or none repeats.
Eigen::VectorXd WithinPlacementCorrelation(const Eigen::MatrixXd& residuals, const std::vector<int>& episode);

}  // namespace dgmm::sim2real
