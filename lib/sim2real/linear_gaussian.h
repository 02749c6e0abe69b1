#pragma once
// The analysis' reference model family: per command a linear-Gaussian conditional
//   x | c, z, f ~ N(W_c^T phi, Sigma_c),  phi = (1, z, z_a z_b[, f])  (q+1),  W_c (q+1) x dx,
// where f = 1 for the first execution after a change of command when the sets carry sequence
// data (so the sim model is p_sim(x | c, z, prev)); without f it is a one-component joint
// Gaussian over y = x || z per command. Small sets (15 real samples
// per command) are handled by shrinkage: the terrain slopes towards the slopes pooled over
// commands (ridge), the covariance towards the pooled residual covariance.
#include <Eigen/Dense>
#include <map>
#include <string>
#include <vector>

#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct LinearGaussianOptions {
  // Ridge on the terrain slopes towards the pooled slopes, as a fraction of the command's own
  // scatter of z (0: no shrinkage).
  double slope_shrinkage = 0.3;
  // Pseudo-count of the pooled residual covariance in each command's covariance.
  double covariance_pseudo_count = 8.0;
  // Added to every covariance diagonal, relative to the pooled residual variance of that entry.
  double relative_floor = 1e-4;
  // Condition on the first-execution flag when the samples carry sequence data.
  bool use_sequence = true;
  // Add the products z_a z_b to the features: responses to the slope direction are not linear in
  // (pitch, roll) (a heading circle maps onto second harmonics).
  bool quadratic_terrain = true;
  bool IsValid(std::string* error) const;
};

// Predictive distribution of one sample: mean and lower Cholesky factor of the covariance.
struct Prediction {
  Eigen::VectorXd mean;
  Eigen::MatrixXd chol;  // L with Sigma = L L^T
  double log_det = 0;    // log det Sigma
};

class LinearGaussianModel {
 public:
  // Fits every command present in `s` (rows listed in `rows`; all rows when empty).
  static LinearGaussianModel Fit(const Samples& s, const LinearGaussianOptions& options,
                                 const std::vector<int>& rows = {});
  // The same fit with another model as the prior (transfer): each command's coefficients and
  // covariance are pulled towards the prior's as if `prior_count` of the prior's samples (with
  // the prior's spread of z) had been observed too. prior_count = 0 is Fit().
  static LinearGaussianModel FitWithPrior(const Samples& s, const LinearGaussianOptions& options,
                                          const std::vector<int>& rows,
                                          const LinearGaussianModel& prior, double prior_count);

  bool HasCommand(int c) const { return commands_.count(c) > 0; }
  int pose_dim() const { return pose_dim_; }
  int terrain_dim() const { return terrain_dim_; }
  bool uses_sequence() const { return use_sequence_; }
  // mean W_c^T phi(z, first) and the command's predictive covariance; commands never seen use
  // the pooled fit. `first` in [0, 1] (a share averages the two cases); ignored without sequence.
  Prediction Predict(int command, const Eigen::Ref<const Eigen::VectorXd>& z, double first = 0.0) const;
  // log N(x; mean, Sigma) for every row of s.
  Eigen::VectorXd LogLikelihood(const Samples& s) const;
  // Residuals x - mean, one row per sample of s.
  Eigen::MatrixXd Residuals(const Samples& s) const;
  // Whitened residuals L^-1 (x - mean), one row per sample of s.
  Eigen::MatrixXd WhitenedResiduals(const Samples& s) const;
  // The command's fitted terrain distribution N(m_z, S_z) (for the joint export).
  Eigen::VectorXd TerrainMean(int c) const;
  Eigen::MatrixXd TerrainCovariance(int c) const;
  std::vector<int> Commands() const;

 private:
  struct PerCommand {
    Eigen::MatrixXd w;  // (dz+1) x dx
    Eigen::MatrixXd a_inv;  // (dz+1) x (dz+1), inverse regularised Gram matrix
    Eigen::MatrixXd gram;   // sum phi phi^T of the command's samples
    double count = 0;
    Eigen::MatrixXd chol;
    double log_det = 0;
    Eigen::VectorXd z_mean;
    Eigen::MatrixXd z_cov;
  };
  Eigen::VectorXd Features(const Eigen::Ref<const Eigen::VectorXd>& z, double first) const;
  // The steps of FitWithPrior (linear_gaussian.cc).
  static void PooledSlopes(const Samples& s, const Eigen::MatrixXd& covariates,
                           const std::map<int, std::vector<int>>& by_command, Eigen::MatrixXd* slopes,
                           Eigen::VectorXd* z_scatter);
  PerCommand FitCommand(const Samples& s, const std::vector<int>& idx, const Eigen::MatrixXd& covariates,
                        const PerCommand* from_prior, double prior_count, const Eigen::MatrixXd& pooled_slopes,
                        const Eigen::VectorXd& z_scatter, double n_rows, const LinearGaussianOptions& options,
                        Eigen::MatrixXd* scatter) const;
  void SetCovariances(const Eigen::MatrixXd& pooled_cov, const std::map<int, Eigen::MatrixXd>& scatter,
                      const std::map<int, std::vector<int>>& by_command, const LinearGaussianModel& prior,
                      double prior_count, const LinearGaussianOptions& options, int p);
  Eigen::VectorXd Phi(const Eigen::Ref<const Eigen::VectorXd>& z, double first) const;
  int pose_dim_ = 0, terrain_dim_ = 0;
  bool use_sequence_ = false;
  bool quadratic_ = false;
  std::map<int, PerCommand> commands_;
  PerCommand pooled_;
};

// log N(x; mean, L L^T) from a Prediction.
double LogNormal(const Eigen::Ref<const Eigen::VectorXd>& x, const Prediction& p);

}  // namespace dgmm::sim2real
