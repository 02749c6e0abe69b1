#pragma once
// Expectation-maximisation for a full-covariance Gaussian mixture: the reference the DGMM is
// compared with (scikit-learn's GaussianMixture semantics: k-means++ init, reg_covar on the
// diagonal, convergence on the change of the mean log-likelihood).
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>

#include "core/mixture.h"

namespace dgmm {

struct EmOptions {
  int components = 2;
  int n_init = 1;                 // restarts; the best final log-likelihood wins
  int max_iterations = 100;
  double tolerance = 1e-3;        // on the change of mean log-likelihood per sample
  double reg_covar = 1e-6;        // added to every covariance diagonal
  std::uint64_t seed = 1;
  bool IsValid(std::string* error) const;
};

struct EmSummary {
  double log_likelihood = 0;       // total, best restart
  double mean_log_likelihood = 0;  // per sample
  int iterations = 0;              // of the best restart
  bool converged = false;
  int restarts = 0;
  double bic = 0;                  // -2 log L + p log n
  std::string BriefReport() const;
};

struct EmResult {
  Mixture mixture;  // weights are responsibilities summed (sum = n)
  EmSummary summary;
};

// Fits a mixture to the rows of X (n x d). Requires n >= components (else InputError).
EmResult FitEm(const Eigen::MatrixXd& X, const EmOptions& options);

// Number of free parameters of a full-covariance mixture: (K-1) + K d + K d(d+1)/2.
int MixtureParameterCount(int components, int dim);

}  // namespace dgmm
