#pragma once
// k-means (Lloyd) with greedy k-means++ seeding, the initialisation of the EM reference. Follows
// scikit-learn's KMeans(n_init=1): 2 + floor(log K) seeding trials per centre, tolerance relative
// to the mean per-dimension variance, empty clusters moved to the farthest points.
#include <Eigen/Dense>
#include <random>
#include <string>
#include <vector>

namespace dgmm {

struct KMeansOptions {
  int clusters = 2;
  int max_iterations = 300;
  // Stop when sum_k |c_k(new) - c_k(old)|^2 <= relative_tolerance * mean_j var(X_j), or when the
  // labels no longer change.
  double relative_tolerance = 1e-4;
  bool IsValid(std::string* error) const;
};

struct KMeansResult {
  Eigen::MatrixXd centers;  // K x d
  Eigen::VectorXi labels;   // n, in [0, K), each sample's nearest centre
  double inertia = 0;       // sum_i |x_i - c_{label_i}|^2
  int iterations = 0;
  bool converged = false;
};

// Greedy k-means++ (Arthur & Vassilvitskii 2007): the first centre is a uniform row, each next
// one the best of 2 + floor(log K) candidates drawn with probability ∝ D(x)^2 (the candidate that
// lowers the potential sum_i D(x_i)^2 most). X is n x d with n >= K >= 1; returns K row indices.
std::vector<int> KMeansPlusPlus(const Eigen::MatrixXd& X, int clusters, std::mt19937_64& rng);

// Lloyd iterations from k-means++ seeds. X is n x d with n >= clusters (asserted).
KMeansResult FitKMeans(const Eigen::MatrixXd& X, const KMeansOptions& options,
                       std::mt19937_64& rng);

// Squared Euclidean distance of every row of X (n x d) to every centre (K x d): n x K.
Eigen::MatrixXd SquaredDistances(const Eigen::MatrixXd& X, const Eigen::MatrixXd& centers);

}  // namespace dgmm
