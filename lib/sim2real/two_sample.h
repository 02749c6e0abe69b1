#pragma once
// Two-sample tests and multiple-comparison control used to locate the mismatch.
#include <Eigen/Dense>
#include <random>
#include <string>
#include <vector>

namespace dgmm::sim2real {

struct MmdOptions {
  int permutations = 1000;
  // RBF bandwidth: median pairwise distance of the pooled sample (the median heuristic) times this.
  double bandwidth_factor = 1.0;
  bool IsValid(std::string* error) const;
};

struct MmdResult {
  double mmd2 = 0;      // unbiased MMD^2 estimate (Gretton et al. 2012)
  double p_value = 1;   // permutation p-value (1 + #{perm >= observed}) / (1 + permutations)
  int n_a = 0, n_b = 0;
};

// Kernel two-sample test between the rows of a (n_a x d) and b (n_b x d) with a Gaussian RBF
// kernel. Fewer than 2 rows on either side: p = 1.
MmdResult MmdTest(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const MmdOptions& options,
                  std::mt19937_64& rng);

// The same test with rows exchangeable only in whole clusters (e.g. the executions of one
// placement, which share the ground under the robot): a permutation reassigns whole clusters, as
// many clusters to a's side as a has. cluster_a[i] labels row i of a, cluster_b row i of b; labels
// are per side (cluster 3 of a and cluster 3 of b are different clusters).
MmdResult MmdTest(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const std::vector<int>& cluster_a,
                  const std::vector<int>& cluster_b, const MmdOptions& options, std::mt19937_64& rng);

// Benjamini-Hochberg adjusted p-values (q-values), same order as p.
std::vector<double> BenjaminiHochberg(const std::vector<double>& p);

}  // namespace dgmm::sim2real
