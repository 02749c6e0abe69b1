#include "em/kmeans.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace dgmm {
namespace {

// Uniform double in [0, 1) from the top 53 bits: the same on every standard library (unlike
// std::uniform_real_distribution), so a seed gives the same model everywhere.
double Uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Uniform integer in [0, n) by multiply-shift (Lemire); bias < n / 2^64.
int UniformIndex(std::mt19937_64& rng, int n) {
  const unsigned __int128 product = static_cast<unsigned __int128>(rng()) * static_cast<unsigned>(n);
  return static_cast<int>(product >> 64);
}

// Squared distance of every row of X to the row vector c: n values.
Eigen::VectorXd SquaredDistancesTo(const Eigen::MatrixXd& X, const Eigen::RowVectorXd& c) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(X.rows());
  for (Eigen::Index j = 0; j < X.cols(); ++j) d.array() += (X.col(j).array() - c(j)).square();
  return d;
}

// Index of the smallest entry of each row of D (first one on ties).
void ArgminRows(const Eigen::MatrixXd& D, Eigen::VectorXi* labels) {
  labels->resize(D.rows());
  for (Eigen::Index i = 0; i < D.rows(); ++i) {
    int best = 0;
    for (Eigen::Index k = 1; k < D.cols(); ++k) {
      if (D(i, k) < D(i, best)) best = static_cast<int>(k);
    }
    (*labels)(i) = best;
  }
}

}  // namespace

bool KMeansOptions::IsValid(std::string* error) const {
  std::string e;
  if (clusters < 1) e = "clusters must be >= 1";
  else if (max_iterations < 1) e = "max_iterations must be >= 1";
  else if (!(relative_tolerance >= 0) || !std::isfinite(relative_tolerance))
    e = "relative_tolerance must be finite and >= 0";
  if (error) *error = e;
  return e.empty();
}

Eigen::MatrixXd SquaredDistances(const Eigen::MatrixXd& X, const Eigen::MatrixXd& centers) {
  Eigen::MatrixXd D(X.rows(), centers.rows());
  for (Eigen::Index k = 0; k < centers.rows(); ++k) D.col(k) = SquaredDistancesTo(X, centers.row(k));
  return D;
}

std::vector<int> KMeansPlusPlus(const Eigen::MatrixXd& X, int clusters, std::mt19937_64& rng) {
  const int n = static_cast<int>(X.rows());
  assert(clusters >= 1 && n >= clusters);
  const int trials = 2 + static_cast<int>(std::log(static_cast<double>(clusters)));
  std::vector<int> indices;
  indices.push_back(UniformIndex(rng, n));
  Eigen::VectorXd closest = SquaredDistancesTo(X, X.row(indices[0]));
  double potential = closest.sum();
  std::vector<double> cumulative(n);
  for (int c = 1; c < clusters; ++c) {
    std::partial_sum(closest.data(), closest.data() + n, cumulative.begin());
    int best_id = -1;
    double best_potential = 0;
    Eigen::VectorXd best_closest;
    for (int t = 0; t < trials; ++t) {
      const double r = Uniform01(rng) * potential;
      // First index whose cumulative sum reaches r (numpy searchsorted, side='left').
      int id = static_cast<int>(std::lower_bound(cumulative.begin(), cumulative.end(), r) -
                                cumulative.begin());
      id = std::min(id, n - 1);
      Eigen::VectorXd candidate = SquaredDistancesTo(X, X.row(id)).cwiseMin(closest);
      const double candidate_potential = candidate.sum();
      if (best_id < 0 || candidate_potential < best_potential) {
        best_id = id;
        best_potential = candidate_potential;
        best_closest = std::move(candidate);
      }
    }
    indices.push_back(best_id);
    closest = std::move(best_closest);
    potential = best_potential;
  }
  return indices;
}

KMeansResult FitKMeans(const Eigen::MatrixXd& X, const KMeansOptions& options,
                       std::mt19937_64& rng) {
  assert(options.IsValid(nullptr));
  const int n = static_cast<int>(X.rows());
  const int K = options.clusters;
  const int d = static_cast<int>(X.cols());
  assert(n >= K);
  // Absolute tolerance: relative_tolerance times the mean population variance of the columns.
  const Eigen::RowVectorXd column_mean = X.colwise().mean();
  const double mean_variance =
      (X.rowwise() - column_mean).array().square().colwise().sum().mean() / n;
  const double tolerance = options.relative_tolerance * mean_variance;

  KMeansResult result;
  const std::vector<int> seeds = KMeansPlusPlus(X, K, rng);
  result.centers.resize(K, d);
  for (int k = 0; k < K; ++k) result.centers.row(k) = X.row(seeds[k]);

  Eigen::VectorXi labels_old = Eigen::VectorXi::Constant(n, -1);
  Eigen::MatrixXd sums(K, d);
  Eigen::VectorXd counts(K);
  bool strict = false;
  for (int it = 0; it < options.max_iterations; ++it) {
    const Eigen::MatrixXd D = SquaredDistances(X, result.centers);
    ArgminRows(D, &result.labels);
    sums.setZero();
    counts.setZero();
    for (int i = 0; i < n; ++i) {
      sums.row(result.labels(i)) += X.row(i);
      counts(result.labels(i)) += 1;
    }
    // Empty clusters take the points farthest from their centres (scikit-learn's relocation).
    std::vector<int> empty;
    for (int k = 0; k < K; ++k) if (counts(k) == 0) empty.push_back(k);
    if (!empty.empty()) {
      std::vector<int> order(n);
      std::iota(order.begin(), order.end(), 0);
      auto far = [&](int a, int b) { return D(a, result.labels(a)) > D(b, result.labels(b)); };
      std::partial_sort(order.begin(), order.begin() + empty.size(), order.end(), far);
      for (size_t e = 0; e < empty.size(); ++e) {
        const int p = order[e], from = result.labels(p);
        sums.row(from) -= X.row(p);
        counts(from) -= 1;
        sums.row(empty[e]) = X.row(p);
        counts(empty[e]) = 1;
      }
    }
    Eigen::MatrixXd centers_new = result.centers;
    for (int k = 0; k < K; ++k) if (counts(k) > 0) centers_new.row(k) = sums.row(k) / counts(k);
    const double shift = (centers_new - result.centers).squaredNorm();
    result.centers = std::move(centers_new);
    result.iterations = it + 1;
    if (result.labels == labels_old) {
      strict = true;
      result.converged = true;
      break;
    }
    if (shift <= tolerance) {
      result.converged = true;
      break;
    }
    labels_old = result.labels;
  }
  // Unless the labels were already stable, relabel against the final centres.
  const Eigen::MatrixXd D = SquaredDistances(X, result.centers);
  if (!strict) ArgminRows(D, &result.labels);
  result.inertia = 0;
  for (int i = 0; i < n; ++i) result.inertia += D(i, result.labels(i));
  return result;
}

}  // namespace dgmm
