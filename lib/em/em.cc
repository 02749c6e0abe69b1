#include "em/em.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "em/em_kernels.h"
#include "em/kmeans.h"
#include "util/error.h"

namespace dgmm {
namespace {

using em_internal::kMaxFixedDim;
using em_internal::NormaliseBlock;
using em_internal::SquaredMahalanobisBlock;
using em_internal::WeightedMoments;

// Added to every component's responsibility sum, as scikit-learn does, so an emptied component
// keeps a finite (tiny) weight and mean instead of dividing by zero.
constexpr double kTinyCount = 10 * std::numeric_limits<double>::epsilon();
const double kLog2Pi = std::log(2 * std::numbers::pi);

// One restart's parameters. Gaussians are kept as the upper factor U of the precision
// (U U^T = Sigma^-1, U = L^-T), so log N(x) = sum log U_jj - 1/2 (d log 2 pi + |(x - mu)^T U|^2).
struct Parameters {
  Eigen::VectorXd log_weights;                      // K, normalised
  Eigen::VectorXd counts;                           // K, responsibilities summed (+ kTinyCount)
  Eigen::MatrixXd means;                            // K x d
  std::vector<Eigen::MatrixXd> covariances;         // K of d x d, reg_covar included
  std::vector<Eigen::MatrixXd> precision_cholesky;  // K of d x d, upper triangular
  Eigen::VectorXd log_det_precision;                // K, sum_j log U_jj
};

// Samples are processed in blocks of kBlock rows so that every intermediate of the E and M steps
// stays in L1 cache (X is n x d column-major: a block of one column is contiguous).
constexpr Eigen::Index kBlock = 256;
// Components whose block pointers fit on the stack for the vectorised normalisation (more: Eigen).
constexpr int kMaxComponentsOnStack = 64;

// The E and M steps over the rows of X (n x d) with the responsibilities (n x K) and block
// buffers allocated once per fit.
class EmWorkspace {
 public:
  EmWorkspace(const Eigen::MatrixXd& X, int components, double reg_covar)
      : X_(X), K_(components), reg_covar_(reg_covar), resp_(X.rows(), components),
        log_prob_(kBlock, components), centred_(kBlock, X.cols()), weighted_(kBlock, X.cols()),
        y_(kBlock), m2_(kBlock), row_max_(kBlock), row_sum_(kBlock) {}

  // Responsibilities from hard labels (the k-means initialisation).
  void SetHardResponsibilities(const Eigen::VectorXi& labels) {
    resp_.setZero();
    for (Eigen::Index i = 0; i < labels.size(); ++i) resp_(i, labels(i)) = 1.0;
  }

  // E-step: r_ik = w_k N_k(x_i) / p(x_i) by log-sum-exp; returns (1/n) sum_i log p(x_i).
  // y = U^T x - U^T mu uses only the upper triangle of U: d(d+1)/2 multiply-adds per sample.
  double EStep(const Parameters& p) {
    const Eigen::Index n = X_.rows(), d = X_.cols();
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> shift(K_, d);  // mu_k^T U_k
    Eigen::VectorXd constant(K_);  // log w_k + log det U_k - d/2 log 2 pi
    for (int k = 0; k < K_; ++k) {
      shift.row(k) = p.means.row(k) * p.precision_cholesky[k];
      constant(k) = p.log_weights(k) + p.log_det_precision(k) - 0.5 * d * kLog2Pi;
    }
    double total = 0;
    for (Eigen::Index i0 = 0; i0 < n; i0 += kBlock) {
      const Eigen::Index b = std::min(kBlock, n - i0);
      auto y = y_.head(b);
      auto m2 = m2_.head(b);
      for (int k = 0; k < K_; ++k) {
        const Eigen::MatrixXd& U = p.precision_cholesky[k];
        if (d <= kMaxFixedDim) {
          const double* cols[kMaxFixedDim];
          for (Eigen::Index a = 0; a < d; ++a) cols[a] = X_.col(a).data() + i0;
          SquaredMahalanobisBlock(cols, b, static_cast<int>(d), U.data(), shift.row(k).data(),
                                  m2.data());
        } else {
          for (Eigen::Index j = 0; j < d; ++j) {
            y = X_.col(0).segment(i0, b).array() * U(0, j) - shift(k, j);
            for (Eigen::Index a = 1; a <= j; ++a) y += X_.col(a).segment(i0, b).array() * U(a, j);
            if (j == 0) m2 = y.square();
            else m2 += y.square();
          }
        }
        log_prob_.col(k).head(b) = constant(k) - 0.5 * m2;
      }
      total += NormaliseRows(i0, b);
    }
    return total / static_cast<double>(n);
  }

  // M-step from the current responsibilities: counts n_k = sum_i r_ik (+ kTinyCount), means and
  // covariances sum_i r_ik (x_i - mu_k)(x_i - mu_k)^T / n_k + reg_covar I, and the precision
  // factors. One pass per component gathers the moments about a shift s near mu_k (the previous
  // means; the first step computes them directly): with F = sum r (x - s), S = sum r (x - s)(x - s)^T
  // and R = sum r, mu = s + F / n_k and n_k Sigma = S - F F^T (2 / n_k - R / n_k^2), exact and free
  // of cancellation because s is close to mu. False when a covariance is not positive definite.
  bool MStep(Parameters* p) {
    const Eigen::Index d = X_.cols();
    const Eigen::VectorXd sums = resp_.colwise().sum().transpose();
    p->counts = sums.array() + kTinyCount;
    p->log_weights = (p->counts / p->counts.sum()).array().log();
    if (p->means.rows() != K_ || p->means.cols() != d) {  // the first step: no previous means
      p->means.noalias() = resp_.transpose() * X_;
      p->means.array().colwise() /= p->counts.array();
    }
    p->covariances.resize(K_);
    p->precision_cholesky.resize(K_);
    p->log_det_precision.resize(K_);
    const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(d, d);
    for (int k = 0; k < K_; ++k) {
      const Eigen::VectorXd shift = p->means.row(k).transpose();
      Eigen::VectorXd first = Eigen::VectorXd::Zero(d);
      Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(d, d);  // lower triangle accumulated
      Moments(k, shift, &first, &cov);
      for (Eigen::Index a = 0; a < d; ++a)
        for (Eigen::Index c = 0; c < a; ++c) cov(c, a) = cov(a, c);
      const double nk = p->counts(k);
      cov -= first * first.transpose() * (2 / nk - sums(k) / (nk * nk));
      p->means.row(k) = (shift + first / nk).transpose();
      cov /= nk;
      cov.diagonal().array() += reg_covar_;
      Eigen::LLT<Eigen::MatrixXd> llt(cov);
      if (llt.info() != Eigen::Success) return false;
      const Eigen::MatrixXd L = llt.matrixL();
      if (!(L.diagonal().array() > 0).all() || !L.allFinite()) return false;
      p->precision_cholesky[k] = L.triangularView<Eigen::Lower>().solve(identity).transpose();
      p->log_det_precision(k) = -L.diagonal().array().log().sum();
      p->covariances[k] = std::move(cov);
    }
    return true;
  }

 private:
  // The block's responsibilities from log_prob_ (rows i0 .. i0 + b of resp_) by log-sum-exp;
  // returns sum_i log p(x_i) over the block.
  double NormaliseRows(Eigen::Index i0, Eigen::Index b) {
    if (K_ <= kMaxComponentsOnStack) {  // the vectorised kernel
      const double* logp[kMaxComponentsOnStack];
      double* resp[kMaxComponentsOnStack];
      for (int k = 0; k < K_; ++k) {
        logp[k] = &log_prob_(0, k);
        resp[k] = resp_.col(k).data() + i0;
      }
      NormaliseBlock(logp, K_, b, resp, row_max_.data(), row_sum_.data());
      return (row_max_.head(b) + row_sum_.head(b).log()).sum();
    }
    auto row_max = row_max_.head(b);
    auto row_sum = row_sum_.head(b);
    row_max = log_prob_.col(0).head(b);
    for (int k = 1; k < K_; ++k) row_max = row_max.max(log_prob_.col(k).head(b));
    row_sum.setZero();
    for (int k = 0; k < K_; ++k) {
      auto r = resp_.col(k).segment(i0, b).array();
      r = (log_prob_.col(k).head(b) - row_max).exp();
      row_sum += r;
    }
    const double total = (row_max + row_sum.log()).sum();
    row_sum = row_sum.inverse();
    for (int k = 0; k < K_; ++k) resp_.col(k).segment(i0, b).array() *= row_sum;
    return total;
  }

  // first += sum_i r_ik (x_i - shift), lower triangle of second += sum_i r_ik (x_i - shift)(x_i - shift)^T.
  void Moments(int k, const Eigen::VectorXd& shift, Eigen::VectorXd* first, Eigen::MatrixXd* second) {
    const Eigen::Index n = X_.rows(), d = X_.cols();
    if (d <= kMaxFixedDim) {
      const double* cols[kMaxFixedDim];
      for (Eigen::Index a = 0; a < d; ++a) cols[a] = X_.col(a).data();
      WeightedMoments(cols, n, static_cast<int>(d), resp_.col(k).data(), shift.data(), first->data(), second->data());
      return;
    }
    for (Eigen::Index i0 = 0; i0 < n; i0 += kBlock) {
      const Eigen::Index b = std::min(kBlock, n - i0);
      const auto r = resp_.col(k).segment(i0, b).array();
      for (Eigen::Index j = 0; j < d; ++j) {
        centred_.col(j).head(b) = X_.col(j).segment(i0, b).array() - shift(j);
        weighted_.col(j).head(b) = centred_.col(j).head(b).array() * r;
        (*first)(j) += weighted_.col(j).head(b).sum();
      }
      for (Eigen::Index a = 0; a < d; ++a)
        for (Eigen::Index c = 0; c <= a; ++c) (*second)(a, c) += weighted_.col(a).head(b).dot(centred_.col(c).head(b));
    }
  }

  const Eigen::MatrixXd& X_;
  int K_;
  double reg_covar_;
  Eigen::MatrixXd resp_;                 // n x K
  Eigen::ArrayXXd log_prob_;             // kBlock x K
  Eigen::MatrixXd centred_, weighted_;   // kBlock x d
  Eigen::ArrayXd y_, m2_, row_max_, row_sum_;  // kBlock
};

// One restart: k-means init, then E/M steps until |change of mean log-likelihood| < tol or
// max_iterations (scikit-learn's loop). nullopt when a covariance fails to factor.
struct RestartResult {
  Parameters parameters;
  std::vector<double> history;
  int iterations = 0;
  bool converged = false;
};

std::optional<RestartResult> RunRestart(const Eigen::MatrixXd& X, const EmOptions& options,
                                        EmWorkspace* work, std::mt19937_64& rng) {
  KMeansOptions kmeans;
  kmeans.clusters = options.components;
  const KMeansResult init = FitKMeans(X, kmeans, rng);
  work->SetHardResponsibilities(init.labels);
  RestartResult r;
  if (!work->MStep(&r.parameters)) return std::nullopt;
  double lower_bound = -std::numeric_limits<double>::infinity();
  for (int it = 1; it <= options.max_iterations; ++it) {
    const double previous = lower_bound;
    lower_bound = work->EStep(r.parameters);
    if (!std::isfinite(lower_bound)) return std::nullopt;
    r.history.push_back(lower_bound);
    if (!work->MStep(&r.parameters)) return std::nullopt;
    r.iterations = it;
    if (std::abs(lower_bound - previous) < options.tolerance) {
      r.converged = true;
      break;
    }
  }
  const double final_ll = work->EStep(r.parameters);
  if (!std::isfinite(final_ll)) return std::nullopt;
  r.history.push_back(final_ll);
  return r;
}

}  // namespace

bool EmOptions::IsValid(std::string* error) const {
  std::string e;
  if (components < 1) e = "components must be >= 1";
  else if (n_init < 1) e = "n_init must be >= 1";
  else if (max_iterations < 0) e = "max_iterations must be >= 0";
  else if (!std::isfinite(tolerance) || tolerance < 0) e = "tolerance must be finite and >= 0";
  else if (!std::isfinite(reg_covar) || reg_covar < 0) e = "reg_covar must be finite and >= 0";
  if (error) *error = e;
  return e.empty();
}

std::string EmSummary::BriefReport() const {
  char buffer[320];
  if (failed) {
    std::snprintf(buffer, sizeof buffer,
                  "EM failed: all %d restarts lost a positive definite covariance "
                  "(increase reg_covar)", restarts);
    return buffer;
  }
  std::snprintf(buffer, sizeof buffer,
                "EM: %d samples, %d restarts (%d failed), best after %d iterations (%s): "
                "mean log-likelihood %.6f, total %.4f, BIC %.4f",
                samples, restarts, failed_restarts, iterations,
                converged ? "converged" : "max iterations", mean_log_likelihood, log_likelihood,
                bic);
  return buffer;
}

int MixtureParameterCount(int components, int dim) {
  return (components - 1) + components * dim + components * dim * (dim + 1) / 2;
}

double BayesianInformationCriterion(double log_likelihood, int samples, int components, int dim) {
  return -2.0 * log_likelihood +
         MixtureParameterCount(components, dim) * std::log(static_cast<double>(samples));
}

EmResult FitEm(const Eigen::MatrixXd& X, const EmOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "EM options", error);
  if (X.rows() == 0 || X.cols() == 0) throw MakeInputError("", "samples", "no samples to fit");
  if (!X.allFinite()) throw MakeInputError("", "samples", "contain NaN or Inf");
  const int n = static_cast<int>(X.rows()), d = static_cast<int>(X.cols());
  if (n < options.components) {
    throw MakeInputError("", "components",
                         std::to_string(n) + " samples are fewer than " +
                             std::to_string(options.components) + " components");
  }
  EmWorkspace work(X, options.components, options.reg_covar);
  std::mt19937_64 rng(options.seed);
  std::optional<RestartResult> best;
  EmResult result;
  result.summary.samples = n;
  result.summary.restarts = options.n_init;
  for (int restart = 0; restart < options.n_init; ++restart) {
    std::optional<RestartResult> r = RunRestart(X, options, &work, rng);
    if (!r) {
      ++result.summary.failed_restarts;
      continue;
    }
    if (!best || r->history.back() > best->history.back()) best = std::move(r);
  }
  if (!best) {
    result.mixture = Mixture(d);
    result.summary.failed = true;
    return result;
  }
  const Parameters& p = best->parameters;
  result.mixture = Mixture(d);
  for (int k = 0; k < options.components; ++k) {
    std::optional<Gaussian> g = Gaussian::Create(p.means.row(k).transpose(), p.covariances[k]);
    assert(g.has_value());  // the same covariance factored in the M-step
    result.mixture.Add(std::exp(p.log_weights(k)) * n, std::move(*g));
  }
  EmSummary& s = result.summary;
  s.mean_log_likelihood = best->history.back();
  s.log_likelihood = s.mean_log_likelihood * n;
  s.iterations = best->iterations;
  s.converged = best->converged;
  s.history = std::move(best->history);
  s.bic = BayesianInformationCriterion(s.log_likelihood, n, options.components, d);
  return result;
}

}  // namespace dgmm
