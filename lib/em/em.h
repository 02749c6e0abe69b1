#pragma once
// Expectation-maximisation for a full-covariance Gaussian mixture: the reference the DGMM is
// compared with (scikit-learn's GaussianMixture semantics: k-means++ init, reg_covar on the
// diagonal, convergence on the change of the mean log-likelihood).
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/mixture.h"

namespace dgmm {

struct EmOptions {
  int components = 2;
  int n_init = 1;                 // restarts; the best final log-likelihood wins
  int max_iterations = 100;       // E+M steps per restart; 0 returns the k-means initialisation
  double tolerance = 1e-3;        // on the change of mean log-likelihood per sample (>= 0)
  double reg_covar = 1e-6;        // added to every covariance diagonal (>= 0)
  std::uint64_t seed = 1;
  // Empty string in *error and true when every field is in range (components >= 1, n_init >= 1,
  // max_iterations >= 0, tolerance and reg_covar finite and >= 0).
  bool IsValid(std::string* error) const;
};

struct EmSummary {
  double log_likelihood = 0;       // total, best restart, of the returned mixture
  double mean_log_likelihood = 0;  // per sample
  int iterations = 0;              // of the best restart (E+M steps, as scikit-learn's n_iter_)
  bool converged = false;          // best restart stopped on the tolerance
  int restarts = 0;                // restarts run
  int failed_restarts = 0;         // restarts whose covariance stopped being positive definite
  bool failed = false;             // every restart failed: the mixture is empty
  double bic = 0;                  // -2 log L + p log n
  int samples = 0;                 // n
  // Mean log-likelihood of the best restart's parameters after 0, 1, ..., iterations M-steps
  // (entry 0: the k-means initialisation); never decreases in exact arithmetic.
  std::vector<double> history;
  std::string BriefReport() const;
};

struct EmResult {
  Mixture mixture;  // weights are responsibilities summed (sum = n)
  EmSummary summary;
};

// Fits a mixture to the rows of X (n x d). Throws InputError when X is empty or not finite, when
// n < components or when the options are invalid. A numerical failure of every restart (a
// covariance that does not factor, e.g. reg_covar = 0 on duplicate points) is reported as
// summary.failed with an empty mixture. Single-threaded; same options (seed), same result.
EmResult FitEm(const Eigen::MatrixXd& X, const EmOptions& options);

// Number of free parameters of a full-covariance mixture: (K-1) + K d + K d(d+1)/2.
int MixtureParameterCount(int components, int dim);

// BIC = -2 log L + p log n with p = MixtureParameterCount(components, dim).
double BayesianInformationCriterion(double log_likelihood, int samples, int components, int dim);

}  // namespace dgmm
