#pragma once
// Sparse selection of effects by cross-validated real likelihood: forward selection that adds,
// of the effects whose held-out gain is significant, the one with the largest gain, bootstrap inclusion
// probabilities and confidence intervals, and the pairs of effects the data cannot tell apart.
#include <Eigen/Dense>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "sim2real/effect_fit.h"

namespace dgmm::sim2real {

struct SelectionOptions {
  int folds = 5;                   // cross-validation folds (grouped by episode)
  double alpha = 0.05;             // family-wise level of each forward step (Bonferroni over candidates)
  double min_gain_nats = 0.01;     // minimal held-out gain per real sample worth an effect
  int max_effects = 4;
  int bootstrap_selection = 20;    // resamples of the whole selection (inclusion probability)
  int bootstrap_parameters = 200;  // resamples of the final fit (confidence intervals)
  double confusion_correlation = 0.8;  // |corr| of fitted shifts above which two effects may be confused
  // After the forward steps, remove one at a time the selected effect whose removal costs the
  // least held-out likelihood while that cost is not significant (same Bonferroni level over the
  // selected effects): an effect that won an early step only because the right one was not yet in
  // the model (e.g. noise inflating the variance of a mean shift) is dropped again.
  bool backward = false;
  EffectFitOptions fit;
  bool IsValid(std::string* error) const;
};

// Fold id per entry of `rows`: whole episodes go to one fold, episodes of each command spread
// round-robin over the folds (so every command keeps training data).
std::vector<int> MakeFolds(const FitProblem& problem, const std::vector<int>& rows, int folds,
                           std::mt19937_64& rng);
// The same from the samples' episode and command ids.
std::vector<int> MakeFolds(const std::vector<int>& episode, const std::vector<int>& command,
                           const std::vector<int>& rows, int folds, std::mt19937_64& rng);

// The rows of fold f held out (`test`, and their positions in `rows`) and the rest (`train`).
struct FoldSplit {
  std::vector<int> train, test, test_pos;
};
FoldSplit SplitFold(const std::vector<int>& rows, const std::vector<int>& fold, int f);

// Held-out log-likelihood per entry of `rows` of the corrected model with `effects`.
Eigen::VectorXd CrossValidate(const FitProblem& problem, const std::vector<int>& effects,
                              const std::vector<int>& rows, const std::vector<int>& fold,
                              const EffectFitOptions& options);

// Mean of d and its standard error with samples clustered by episode.
void ClusteredMean(const Eigen::VectorXd& d, const std::vector<int>& cluster, double* mean, double* se);

struct CandidateScore {
  int effect = -1;
  double gain = 0;  // held-out nats per real sample over the current model
  double se = 0;
  double z = 0;
};

struct SelectionStep {
  int chosen = -1;                      // library index, -1: stopped here
  std::vector<CandidateScore> candidates;  // the chosen one first, then by gain
  // Other candidates whose gain is within one SE of the chosen one and whose fitted predictions
  // correlate strongly with it: the data cannot tell them apart.
  std::vector<int> confusable;
  double threshold_z = 0;
};

struct SelectionResult {
  std::vector<int> selected;            // library indices, in order of selection
  std::vector<SelectionStep> steps;
  std::vector<int> removed;             // library indices dropped by the backward pass, in order
  // Per selected effect: held-out nats per real sample lost when it alone is removed from the
  // final set (its importance given the others; effects are ranked by it).
  std::vector<double> importance;
  EffectFit fit;                        // final fit on all real samples
  Eigen::VectorXd heldout_corrected;    // per real sample, corrected model, same folds
  Eigen::VectorXd heldout_sim;          // per real sample, sim model (no fitting involved)
};

SelectionResult ForwardSelect(const FitProblem& problem, const std::vector<int>& rows,
                              const std::vector<int>& fold, const SelectionOptions& options);

struct BootstrapResult {
  std::vector<double> inclusion;                  // per library effect, share of resamples
  std::vector<std::vector<int>> selections;       // per resample, the effects it selected
  std::vector<Eigen::VectorXd> lower, upper;      // per selected effect, 95% percentile interval
};

// z with P(Z > z) = p for a standard normal (bisection on erfc; p in (0, 1)).
double UpperQuantile(double p);

// The candidate with the largest held-out z at the first selection step (nullptr: no step or none).
const CandidateScore* FirstStepBest(const SelectionResult& selection);

BootstrapResult Bootstrap(const FitProblem& problem, const SelectionResult& selection,
                          const SelectionOptions& options, std::mt19937_64& rng);

}  // namespace dgmm::sim2real
