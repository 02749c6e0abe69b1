#pragma once
// The check by simulation of a discriminating experiment proposed for two tied simulator knobs
// (docs/sim2real.md, "The experiment check"): the robot is simulated at each knob's fitted value
// in the proposed command x terrain cell, with the same seed (common random numbers: the same
// placements and sensor noise), and the two outcome sets are compared.
#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "sim2real/knob_simulator.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real {

struct ExperimentCheckOptions {
  bool enabled = true;          // --no-experiment-check: false
  std::uint64_t seed = 1;       // placements and sensor noise of the cell (shared by both runs)
  int min_executions = 20;      // simulated at least, to measure the separation per execution
  int max_executions = 100;     // simulated at most per knob value (the cost bound)
  int executions_per_placement = 5;
  double z_required = 3.42;     // the proposal's criterion: one-sided alpha 0.005 (2.58) + power 0.8 (0.84)
  double alpha = 0.005;         // level of the paired sign-flip test
  int permutations = 2000;
  int threads = 2;              // the two runs in parallel
  bool IsValid(std::string* error) const;
};

// Executions of a cell that separate two predictions d2 apart (squared whitened distance per
// execution) by a one-sided test at alpha 0.005 (2.58 sigma) with power 0.8 (0.84):
// ceil((2.58 + 0.84)^2 / d2) = ceil(11.7 / d2). d2 > 0. Used by the proposal (knob_analysis.cc)
// and by its check here, so both apply the same criterion.
int ExecutionsToSeparate(double d2);

// Separation of paired outcome sets a (n x dx) and b (rows paired by common random numbers):
//   D_i = a_i - b_i, delta = mean D, S_D = cov D, Sigma = s^2 x the pooled within-set covariance
//   of a and b (the spread one recording of the cell shows; s = spread_scale, e.g. the real set's
//   fitted noise scale when it is above 1),
//   d2 = max(0, delta^T Sigma^-1 delta - tr(Sigma^-1 S_D) / n)  (squared whitened distance per
//        execution, debiased for the estimation error of delta),
//   z = sqrt(N d2) for N proposed executions (expected z of N recorded executions against the
//       other value's prediction), executions_needed = ExecutionsToSeparate(d2),
//   p = sign-flip permutation p-value of T = delta^T Sigma^-1 delta (H0: no difference in the cell).
struct PairedSeparation {
  int pairs = 0;
  double d2 = 0, z = 0, p_value = 1;
  int executions_needed = -1;  // -1: no separation measured (d2 = 0)
};
// Throws InputError for fewer than dx + 2 pairs or mismatched shapes.
PairedSeparation SeparationOfPairs(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, int proposed_executions,
                                   int permutations, std::uint64_t seed, double spread_scale = 1.0);

struct ExperimentCheck {
  bool checked = false;
  std::string why_not;          // when not checked
  int executions_proposed = 0, executions_simulated = 0, placements = 0;
  std::uint64_t seed = 0;
  double heading_deg = NAN;     // where the simulator stood the robot for the cell's terrain
  std::string placement;        // the same in words
  double spread_scale = 1;      // the simulated spread was scaled by this (SeparationOfPairs)
  std::vector<std::string> knobs;
  std::vector<double> values;   // the two simulated values (one knob each)
  PairedSeparation separation;
  bool confirmed = false;       // z >= z_required and p < alpha
  double seconds = 0;
};

// Records the cell (command, terrain as the sim set's columns) at knob value `a` and at `b`,
// max(min, min(proposed, max)) executions each, paired by the simulator's common random numbers,
// and measures their separation. Throws InputError when a simulation fails.
ExperimentCheck CheckExperiment(const KnobSimulator& simulator, const KnobValue& a, const KnobValue& b,
                                const Eigen::VectorXd& command, const Eigen::VectorXd& terrain,
                                int proposed_executions, const ExperimentCheckOptions& options,
                                double spread_scale = 1.0);

// Writes the check into the verdict's experiment (checked_by_simulation, confirmed, simulation).
void RecordCheck(const ExperimentCheck& check, double z_required, VerdictExperiment* experiment);

}  // namespace dgmm::sim2real
