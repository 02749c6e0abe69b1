#pragma once
// Dynamic Gaussian Mixture Model (Edgington, Kassahun & Kirchner, Algorithm 2 ADDSAMPLE):
// samples arrive one at a time and either merge into a component or start a new one, decided by
// t = 1 - (1 - d) exp(-k n), d = p(x) / max p. No sample history is kept.
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "core/dgmm_options.h"
#include "core/mixture.h"

namespace dgmm {

// Sufficient statistics of one component: n samples, their mean and scatter
// M2 = sum (x - mean)(x - mean)^T; nothing else about the samples is kept.
struct DgmmComponentStats {
  std::int64_t count = 0;
  Eigen::VectorXd mean;
  Eigen::MatrixXd scatter;
};

// What ADDSAMPLE did with one sample.
struct AddSampleResult {
  bool merged = false;             // false: a new component was started.
  int component = -1;              // index of the component that received the sample.
  double threshold = 0;            // t; when d was not needed, the lower bound 1 - exp(-k n) <= t
  bool density_evaluated = false;  // whether d = p(x) / max p was computed for this sample
};

class Dgmm {
 public:
  // dim-dimensional model; options must be valid (asserted).
  Dgmm(int dim, DgmmOptions options);

  int dim() const { return dim_; }
  const DgmmOptions& options() const { return options_; }
  // n: samples added so far.
  std::int64_t num_samples() const { return num_samples_; }
  // The current model: weights are sample counts, covariances the floored per-component ones.
  const Mixture& mixture() const { return mixture_; }
  const std::vector<DgmmComponentStats>& stats() const { return stats_; }
  // Unbiased sample covariance M2 / (n - 1) of component i (before any floor); n >= 2.
  Eigen::MatrixXd SampleCovariance(int i) const;

  // ADDSAMPLE (Algorithm 2) for x (dim entries, finite: asserted).
  AddSampleResult AddSample(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng);

  // Covariance the model uses for a component with these statistics: the options' covariance
  // rule (core/dgmm_options.h: literal, blend or prior) applied to (n, M2, S0), plus floor I.
  Eigen::MatrixXd FlooredCovariance(const DgmmComponentStats& stats) const;
  // log max_x p(x) (cached until the components change); -inf when empty.
  double MaxLogDensity() const;
  // Upper bound log sum_i w_i max_x N_i(x) / W >= log max p, O(k).
  double PeakLogDensityBound() const;
  // True once options().max_components stopped the mixture from growing.
  bool max_components_hit() const { return max_components_hit_; }

 private:
  // Algorithm 2 as written (options_.variant == kFaithful).
  AddSampleResult AddSampleFaithful(const Eigen::Ref<const Eigen::VectorXd>& x,
                                    std::mt19937_64& rng);
  // Algorithm 2's decision, shared by both variants: draws r ~ U(0,1) and sets threshold t,
  // merged = r < t and density_evaluated (component is left at -1).
  AddSampleResult DecideMerge(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng);
  // The improved variant (lib/core/dgmm_improved.cc).
  AddSampleResult AddSampleImproved(const Eigen::Ref<const Eigen::VectorXd>& x,
                                    std::mt19937_64& rng);
  // New component: mean x, initial covariance, weight 1. Returns its index.
  int StartComponent(const Eigen::Ref<const Eigen::VectorXd>& x);
  // Eqs. 11-13 for component i (Welford form), then refactors its Gaussian.
  void MergeInto(int i, const Eigen::Ref<const Eigen::VectorXd>& x);
  // Component index drawn with probability proportional to w_i exp(-1/2 m_i^2(x)).
  int ChooseComponent(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng);
  // FlooredCovariance written into *cov (reusing its storage); for the improved variant M2 is
  // its weighted scatter (n - 1) C_w.
  void FloorInto(const DgmmComponentStats& stats, Eigen::MatrixXd* cov) const;
  // Rebuilds mixture_ component i from stats_[i] with the floor (a new factorisation).
  void RefreshComponent(int i);
  // After a merge into component i (count n -> n + 1, scatter += c delta delta^T with delta in
  // delta_scratch_ and c in update_weight_): updates its factor by one rank-one step when the
  // covariance rule allows it (core/dgmm.cc); false when component i needs RefreshComponent.
  bool RankOneRefresh(int i);
  // The covariance rule as cov = scatter_scale * M2 + prior_weight * S0 (+ floor) for `count`.
  void CovarianceCoefficients(std::int64_t count, double* scatter_scale,
                              double* prior_weight) const;

  int dim_;
  DgmmOptions options_;
  std::int64_t num_samples_ = 0;
  Mixture mixture_;
  std::vector<DgmmComponentStats> stats_;
  Eigen::VectorXd initial_diagonal_;  // S0's diagonal, resolved (ones for identity)
  mutable bool max_valid_ = false;    // max_log_density_ is up to date
  mutable double max_log_density_ = 0.0;
  mutable Eigen::VectorXd last_mode_;   // argmax of the last mode search (a lower bound)
  // Incremental mode search: weights at the last search (a changed weight marks a changed
  // component) and the component count at the last search from every mean.
  mutable std::vector<double> searched_weights_;
  mutable int full_search_size_ = 0;
  bool max_components_hit_ = false;
  std::vector<double> log_choice_;      // scratch for ChooseComponent
  Eigen::MatrixXd covariance_scratch_;  // scratch for RefreshComponent
  Eigen::VectorXd delta_scratch_;       // delta = x - mean from MergeInto
  Eigen::VectorXd update_scratch_;      // e = sqrt(c) delta there
  double update_weight_ = 0.0;          // c = w / w' there
  // L_i^-1 (x - mean_i) of every component from ChooseComponent (component i at i * dim), which
  // the merge's rank-one update reuses for whitened_component_ (-1: none valid).
  std::vector<double> whitened_;
  int whitened_component_ = -1;
  // Per component: the floor currently inside its factor (it shrinks with the rest of the
  // covariance between factorisations) and rank-one updates since its last factorisation.
  std::vector<double> factor_floor_;
  std::vector<int> updates_since_factor_;
};

}  // namespace dgmm
