#pragma once
// Scores simulator configs against the real set by re-simulation (used by recalibrate.cc).
//
// A model trained on a small re-simulated set (40 placements) is too noisy to compare configs
// directly, so a config is scored through what it changes: each re-simulated set is projected on
// the mean-effect family E selected by the analysis (design D = [D_e ...], P columns),
//   theta(set) = argmin sum_k || L_k^-1 (x_k - u_k - D_k theta) ||^2   (u_k, L_k: sim model),
// and the config's shift is theta(config) - theta(nominal), both simulated with the same seed
// (common random numbers: the sampling noise of the two fits largely cancels). Its score is the
// mean real log-likelihood under the sim model moved by that shift,
//   ll(theta) = mean_r log N(x_r; u_r + D_r theta, Sigma_r).
// Sets are cached by config, simulated in parallel (std::thread), each with the same seed.
#include <Eigen/Dense>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/sim_config.h"
#include "sim2real/pipeline.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct ResimOptions {
  std::uint64_t seed = 1;
  int placements = 40;  // per re-simulation (protocol paper-830: random headings, 5 executions)
  int threads = 2;
  bool IsValid(std::string* error) const;
};

struct ResimScore {
  bool ok = false;
  std::string error;           // why the simulation failed (ok = false)
  int samples = 0;
  Eigen::VectorXd shift;       // theta(config) - theta(nominal), P
  double mean_log_likelihood = 0;  // ll(shift) per real sample
};

class ResimScorer {
 public:
  // `effects`: the mean effects to project on (noise effects are ignored). Throws InputError
  // when the real set's commands cannot be matched to the sim model's.
  ResimScorer(const Sim2RealResult& result, const SampleSet& real, const sim::SimConfig& nominal,
              const std::vector<EffectSpec>& effects, const ResimOptions& options);

  // Simulates the configs not yet seen (in parallel) and returns their scores, in order.
  std::vector<ResimScore> Evaluate(const std::vector<sim::SimConfig>& configs);
  // ll(theta) for any shift theta (P).
  double LogLikelihood(const Eigen::VectorXd& theta) const;
  // Coefficients s (q) maximising ll(basis * s), basis P x q (weighted least squares; ridge
  // `ridge` relative to the mean diagonal against singular bases).
  Eigen::VectorXd FitCoefficients(const Eigen::MatrixXd& basis, double ridge = 1e-6) const;
  // Mean real log-likelihood of the sim model alone (theta = 0).
  double NominalLogLikelihood() const { return LogLikelihood(Eigen::VectorXd::Zero(num_params_)); }
  // Direct check: mean real log-likelihood of linear-Gaussian models trained on re-simulations
  // of each config with `placements` placements (seed + 1), e.g. {nominal, recalibrated}.
  std::vector<double> DirectLogLikelihoods(const std::vector<sim::SimConfig>& configs,
                                           int placements);
  int num_params() const { return num_params_; }
  int simulations() const { return simulations_; }
  const sim::SimConfig& nominal() const { return nominal_; }

 private:
  // Normal equations of the whitened problem over a set of samples, y_k = L_k^-1 (x_k - u_k),
  // W_k = L_k^-1 D_k under the sim model (the analysis' own FitProblem, effect_fit.h).
  struct Projection {
    Eigen::MatrixXd a;     // sum W^T W (P x P)
    Eigen::VectorXd b;     // sum W^T y (P)
    double yy = 0;         // sum y^T y
    double log_norm = 0;   // sum (-log det Sigma_k / 2 - dx log(2 pi) / 2)
    int n = 0;
  };
  // Simulates each config (same seed) in parallel; failed ones come back empty with an error.
  std::vector<SampleSet> Simulate(const std::vector<sim::SimConfig>& configs, int placements,
                                  std::uint64_t seed, std::vector<std::string>* errors);
  Projection Project(const Samples& samples) const;
  // Set command row -> sim model command (by label, else via the values of the real set).
  std::vector<int> CommandMap(const SampleSet& set) const;
  Eigen::VectorXd Solve(const Projection& p) const;

  const Sim2RealResult& result_;
  const SampleSet& real_;
  sim::SimConfig nominal_;
  std::vector<EffectSpec> effects_;
  ResimOptions options_;
  int num_params_ = 0;
  int simulations_ = 0;
  Projection real_projection_;  // of the real samples
  SampleSet nominal_set_;         // the nominal re-simulation (command table anchor)
  Eigen::VectorXd nominal_theta_;  // theta(nominal)
  std::map<std::string, ResimScore> cache_;  // by SimConfigToJson
};

}  // namespace dgmm::sim2real
