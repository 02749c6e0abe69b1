#pragma once
// Is what remains after a correction structured, or a pure change of scale? Permutation tests on
// the whitened residuals r_i (n x dx) of the corrected model, with placements (episodes) as the
// exchangeable units, so the correlation of one placement's samples cannot fake structure:
//   command:  between-command sum of squares of the episode means (labels permuted over episodes),
//             or with the sim set's own residuals (SimReference) the difference of the two sets'
//             command means, sum_c w_c |m_real,c - m_sim,c|^2 with w_c = N_real,c N_sim,c /
//             (N_real,c + N_sim,c) (set labels permuted over each command's episodes)
//   terrain:  the same over terrain regions (nearest k-means centre of each episode's mean z)
//   step:     sum of squares of the step-index means of r_i - (episode mean) (steps permuted
//             within each episode), or of their difference from the sim set's own residuals'
//             (SimReference); "periodic" when the step means alternate in sign (lag-1
//             autocorrelation of the step-mean profile < -0.3)
//   tails:    excess kurtosis of |r_i|^2-normalised residuals over the sim set's own
//             (a difference > max(1, 4 SE) with SE = sqrt(24 / (n dx)), or with tails_bootstrap,
//             which the analysis sets on every ground, the two kurtoses' placement-bootstrap SEs
//             combined)
// Bonferroni over the four tests.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

namespace dgmm::sim2real {

struct ResidualStructureOptions {
  int permutations = 1000;
  // > 0: the tails test's SE from this many bootstrap resamples of placements (rough ground, where
  // a few placements hang up and a sample-count SE is far too small); 0: sqrt(24 / (n dx)).
  int tails_bootstrap = 0;
  double alpha = 0.01;  // family-wise over the four tests
  bool IsValid(std::string* error) const;
};

struct ResidualTest {
  std::string where;      // "command", "terrain", "step", "periodic", "tails"
  double statistic = 0;
  double p_value = 1;
  bool significant = false;
};

struct ResidualStructure {
  std::vector<ResidualTest> tests;
  std::vector<std::string> structured_in;  // the significant `where`s
  Eigen::VectorXd step_profile;            // mean whitened residual norm direction per step
};

// The sim set's own residuals (cross-fitted), placements, execution indices and commands: with them
// the step test asks whether the real set's step profile differs from the sim set's, and the command
// test whether the real set's command means differ from the sim set's (what the model leaves in
// both: its own estimation error and misfit per command), not from none. Null pointers: the
// one-set tests.
struct SimReference {
  const Eigen::MatrixXd* residuals = nullptr;
  const std::vector<int>* episode = nullptr;
  const std::vector<int>* step = nullptr;
  const std::vector<int>* command = nullptr;
  // Residuals and placements given, with at least one row (what every two-set test needs).
  bool has_residuals() const { return residuals && episode && residuals->rows() > 0; }
};

// `residuals` n x dx; `command`, `terrain` (region id, -1: none), `episode`, `step` per sample
// (step -1: no sequence data); `sim_kurtosis` the excess kurtosis of the sim set's own
// whitened residuals (NaN: skip the tails test) and `sim_kurtosis_se` its standard error (used
// with options.tails_bootstrap).
ResidualStructure TestResidualStructure(const Eigen::MatrixXd& residuals, const std::vector<int>& command,
                                        const std::vector<int>& terrain, const std::vector<int>& episode,
                                        const std::vector<int>& step, double sim_kurtosis,
                                        const ResidualStructureOptions& options, std::uint64_t seed,
                                        double sim_kurtosis_se = 0, const SimReference& sim_ref = {});

// Mean excess kurtosis over the columns of r (n x dx).
double ExcessKurtosis(const Eigen::MatrixXd& r);

// Its standard error over `resamples` bootstrap resamples of whole placements (`episode` per row).
double ExcessKurtosisSe(const Eigen::MatrixXd& r, const std::vector<int>& episode, int resamples, std::uint64_t seed);

}  // namespace dgmm::sim2real
