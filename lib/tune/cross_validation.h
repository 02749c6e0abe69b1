#pragma once
// Repeated K-fold cross-validation (whole episodes per fold, else stratified by command) of motion models, as in Table I of Edgington et al.:
// per repeat, the held-out log-likelihood summed over every validation fold,
//   L_r = sum_f sum_{i in fold f} log p(x_i | c_i [, z_i]; model trained on the other folds),
// for the DGMM without terrain (p(x | c)) and with it (p(x | c, z)), and for an EM baseline per
// command whose number of components is chosen by BIC on the training fold.
#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/motion_model.h"
#include "core/sample_set.h"
#include "em/em.h"

namespace dgmm {

// fold[i] in 0..folds-1 for each of the n = command.size() samples, stratified by command: each
// command's samples are shuffled (rng) and dealt round-robin into the folds, the deal continuing
// where the previous command stopped, so every fold gets floor or ceil of each command's share
// and fold sizes differ by at most one. A command with fewer samples than folds is absent from
// some folds (never duplicated). folds >= 1 (asserted).
std::vector<int> StratifiedFolds(const Eigen::VectorXi& command, int folds, std::mt19937_64& rng);

// fold[i] in 0..folds-1 for each sample, grouped by episode: the distinct episode ids are
// shuffled (rng) and each is given whole to the fold with the fewest samples so far (lowest
// index on ties), so no episode is split across folds and fold sizes stay close. Needs at least
// `folds` distinct episodes (asserted).
std::vector<int> EpisodeFolds(const Eigen::VectorXi& episode, int folds, std::mt19937_64& rng);

// A seed for one independent stream, mixed (splitmix64) from a base seed and up to three indices
// (e.g. repeat, fold, purpose). The same inputs always give the same seed.
std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0,
                         std::uint64_t c = 0);

struct CvOptions {
  // DGMM settings (k, variant, initial covariance, floor); with_terrain and seed are set per fold.
  DgmmOptions dgmm;
  // 0: chosen from the data (tune/fold_plan.h ChooseFolds: leave-one-episode-out for few
  // episodes); >= 2: that many.
  int folds = 10;
  int repeats = 10;
  // Base seed: repeat r's fold assignment and fold f's merge decisions draw from
  // DeriveSeed(seed, r, f, .), so results do not depend on the thread count, and two runs that
  // differ only in k see the same folds and the same random numbers (common random numbers).
  std::uint64_t seed = 1;
  // false (default): each training fold streams its samples in the set's recorded order, as the
  // robot produced them (ADDSAMPLE is order dependent). true: shuffled per (repeat, fold).
  bool shuffle_training = false;
  // true (default): when the set has episode data with at least `folds` episodes (two for
  // automatic folds), folds hold whole episodes (EpisodeFolds), so windows of one drive never fall
  // on both sides; otherwise (or when false) stratified by command (StratifiedFolds).
  bool group_by_episode = true;
  // Which rows of the table to compute. With terrain needs a set with terrain (else skipped).
  bool without_terrain = true;
  bool with_terrain = true;
  bool em_baseline = true;
  // EM baseline: per command, components K in 1..em_max_components whose free parameters
  // (K-1) + K d + K d(d+1)/2 do not exceed n_train (K = 1 always tried); lowest BIC wins. With
  // fewer samples than parameters, EM finds near-singular components whose unbounded likelihood
  // outgrows BIC's penalty (with 27 samples in 4-D BIC picked K = 5 over the true K = 1).
  int em_max_components = 5;
  EmOptions em{.components = 1, .n_init = 3};
  // Worker threads for the (repeat, fold) tasks; 0: std::thread::hardware_concurrency().
  int threads = 0;
  // Called after each finished task with (done, total), from worker threads (serialised).
  std::function<void(int, int)> progress;

  bool IsValid(std::string* error) const;
};

// One row of the table: the held-out log-likelihood totals of one model family.
struct CvScore {
  bool evaluated = false;
  std::vector<double> per_repeat;  // L_r, total over all validation folds of repeat r
  Eigen::MatrixXd per_fold;        // repeats x folds, totals of each validation fold
  double mean = 0;                 // mean of L_r over repeats
  double sd = 0;                   // sample sd of L_r over repeats (0 when repeats == 1)
  // sqrt(n_scored) * sd of the per-sample held-out log-likelihoods, averaged over repeats: the
  // spread of L expected from another sample of the same size (repeats reuse the same data, so
  // they are averaged, not counted as independent).
  double standard_error = 0;
  double mean_per_sample = 0;  // mean / n_scored
  // The mean over folds and commands of the number of components (EM: the K BIC chose; DGMM:
  // the Gaussians the pass ended with).
  double mean_components = 0;
};

// What conditioning on terrain changes for one model family, L(with) - L(without). Both rows score
// the same held-out samples with the same folds, so its standard error is that of the paired
// per-sample differences, sqrt(n_scored) * sd(l_i(with) - l_i(without)), averaged over repeats:
// smaller than either row's own when the two models agree on which samples are hard.
struct CvTerrainChange {
  bool evaluated = false;
  double mean = 0;            // mean over repeats of L_r(with) - L_r(without)
  double standard_error = 0;  // of the paired differences
};

struct CvSummary {
  int samples = 0;
  int commands = 0;
  int folds = 0;
  int repeats = 0;
  // Held-out samples scored per repeat. A validation sample whose command has no sample in its
  // training fold (a command with a single sample) cannot be scored and is counted in unscored.
  int scored_per_repeat = 0;
  int unscored_per_repeat = 0;
  bool has_terrain = false;
  // How the folds were made and why, stated in every report (FoldPlan::reason), e.g.
  // "leave-one-episode-out (6 episodes)" or "5 folds stratified by command (asked)".
  std::string folds_by;
  CvScore dgmm_without_terrain, dgmm_with_terrain, em_without_terrain, em_with_terrain;
  CvTerrainChange dgmm_terrain_change, em_terrain_change;  // evaluated when both rows are
  // Non-empty when that EM-BIC row was asked for but omitted, and why (a command with fewer
  // training samples than the parameters of one full-covariance Gaussian: EM would fit noise).
  std::string em_without_terrain_omitted, em_with_terrain_omitted;
  double seconds = 0;  // wall time
  std::string BriefReport() const;
};

// Throws InputError for an empty or inconsistent set; options must be valid (InputError otherwise).
CvSummary CrossValidate(const SampleSet& set, const CvOptions& options);

// Per-command EM with BIC model selection on the rows of Y (n x d): the fit with the lowest BIC
// over the candidate component counts of CvOptions. Returns the mixture and sets *components.
Mixture FitEmByBic(const Eigen::MatrixXd& Y, const EmOptions& em, int max_components,
                   int* components);

}  // namespace dgmm
