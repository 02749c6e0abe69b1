#include "tune/cross_validation.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>

#include "tune/fold_plan.h"
#include "util/error.h"
#include "util/parallel_for.h"

namespace dgmm {
namespace {

// Rows of the table, in the order of CvSummary's members.
enum Variant { kDgmmWithout = 0, kDgmmWith = 1, kEmWithout = 2, kEmWith = 3, kVariants = 4 };

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// What one (repeat, fold) task produced.
struct FoldResult {
  std::array<std::vector<double>, kVariants> per_sample;  // scored validation samples
  std::array<double, kVariants> components{};             // sum of K over commands
  int em_commands = 0;
  int dgmm_commands = 0;  // per terrain setting
  int unscored = 0;
};

// Sum of log|scale| over the pose dimensions: the Jacobian that maps a log-density of
// standardised x back to raw units (0 when the set is not standardised).
double PoseLogJacobian(const SampleSet& set) {
  if (set.transform.empty()) return 0.0;
  return set.transform.scale.head(set.pose_dim()).array().abs().log().sum();
}

double HeldOut(const MotionModel& model, const SampleSet& set, int i, bool terrain) {
  const Eigen::VectorXd x = set.x.row(i).transpose();
  if (!terrain) return model.LogLikelihood(set.command(i), x);
  const Eigen::VectorXd z = set.z.row(i).transpose();
  return model.LogLikelihood(set.command(i), x, z);
}

// The EM baseline on the same training fold: one BIC-selected mixture per command, in the same
// model header (dimensions, names, transform) as the DGMM so that scoring is identical.
MotionModel FitEmModel(const SampleSet& train, const MotionModel& header, bool terrain,
                       const CvOptions& options, std::uint64_t seed, double* components_sum,
                       int* commands) {
  MotionModel model = header;
  model.kind = "em";
  model.mixtures.clear();
  std::map<int, std::vector<int>> rows_of;
  for (int i = 0; i < train.size(); ++i) rows_of[train.command(i)].push_back(i);
  const int d = train.pose_dim() + (terrain ? train.terrain_dim() : 0);
  for (const auto& [c, rows] : rows_of) {
    Eigen::MatrixXd Y(static_cast<int>(rows.size()), d);
    for (int r = 0; r < Y.rows(); ++r) {
      Y.row(r).head(train.pose_dim()) = train.x.row(rows[r]);
      if (terrain) Y.row(r).tail(train.terrain_dim()) = train.z.row(rows[r]);
    }
    EmOptions em = options.em;
    em.seed = DeriveSeed(seed, static_cast<std::uint64_t>(c));
    int k = 0;
    model.mixtures[c] = FitEmByBic(Y, em, options.em_max_components, &k);
    *components_sum += k;
    ++*commands;
  }
  return model;
}

// em_for[terrain]: fit and score the EM baseline for that terrain setting.
FoldResult RunFold(const SampleSet& set, const std::vector<int>& fold_of, int repeat, int fold,
                   const CvOptions& options, bool has_terrain, std::array<bool, 2> em_for) {
  const std::uint64_t seed = DeriveSeed(options.seed, repeat, fold, 1);
  std::vector<int> train_rows, valid_rows;
  for (int i = 0; i < set.size(); ++i) (fold_of[i] == fold ? valid_rows : train_rows).push_back(i);
  if (options.shuffle_training) {
    std::mt19937_64 shuffle_rng(DeriveSeed(seed, 2));
    std::shuffle(train_rows.begin(), train_rows.end(), shuffle_rng);
  }
  const SampleSet train = set.Subset(train_rows);
  const double jacobian = PoseLogJacobian(set);

  FoldResult result;
  for (bool terrain : {false, true}) {
    if (terrain ? !(options.with_terrain && has_terrain) : !options.without_terrain) continue;
    MotionModelOptions model_options;
    model_options.dgmm = options.dgmm;
    // An initial covariance given for y = x || z applies to x alone without terrain.
    Eigen::VectorXd& init = model_options.dgmm.initial_covariance_diagonal;
    if (!terrain && init.size() == set.pose_dim() + set.terrain_dim() && set.terrain_dim() > 0) {
      init = init.head(set.pose_dim()).eval();
    }
    model_options.with_terrain = terrain;
    model_options.seed = seed;  // the same stream with and without terrain, and for every k
    const MotionModel dgmm_model = LearnMotionModel(train, model_options);
    result.dgmm_commands = static_cast<int>(dgmm_model.mixtures.size());
    for (const auto& [c, mixture] : dgmm_model.mixtures) {
      result.components[terrain ? kDgmmWith : kDgmmWithout] += mixture.size();
    }
    MotionModel em_model;
    const int em_variant = terrain ? kEmWith : kEmWithout;
    if (em_for[terrain]) {
      int commands = 0;
      em_model = FitEmModel(train, dgmm_model, terrain, options, DeriveSeed(seed, 3, terrain),
                            &result.components[em_variant], &commands);
      result.em_commands = commands;  // the same commands for either terrain setting
    }
    int unscored = 0;
    for (int i : valid_rows) {
      if (!dgmm_model.HasCommand(set.command(i))) {
        ++unscored;
        continue;
      }
      result.per_sample[terrain ? kDgmmWith : kDgmmWithout].push_back(
          HeldOut(dgmm_model, set, i, terrain) - jacobian);
      if (em_for[terrain]) {
        result.per_sample[em_variant].push_back(HeldOut(em_model, set, i, terrain) - jacobian);
      }
    }
    result.unscored = unscored;
  }
  return result;
}

// Why the EM-BIC row over d dimensions is omitted: in some training fold a command has fewer
// samples than the d + d(d+1)/2 parameters of one full-covariance Gaussian, so unregularised EM
// fits noise (near-singular covariances, held-out log-likelihoods of -1e5 and worse); "" when
// every command has enough in every training fold.
std::string EmUnderdetermined(const SampleSet& set, const std::vector<std::vector<int>>& fold_of,
                              int folds, int d) {
  const int parameters = d + d * (d + 1) / 2;
  std::map<int, int> total;
  for (int i = 0; i < set.size(); ++i) ++total[set.command(i)];
  int worst_command = -1, worst = parameters;
  for (const std::vector<int>& assignment : fold_of) {
    for (int f = 0; f < folds; ++f) {
      std::map<int, int> train = total;
      for (int i = 0; i < set.size(); ++i) train[set.command(i)] -= assignment[i] == f;
      for (const auto& [c, n] : train) {
        if (n > 0 && n < worst) worst = n, worst_command = c;
      }
    }
  }
  if (worst_command < 0) return "";
  const std::string name = worst_command < static_cast<int>(set.command_labels.size())
                               ? "'" + set.command_labels[worst_command] + "'"
                               : std::to_string(worst_command);
  return "command " + name + " has " + std::to_string(worst) +
         " training samples in a fold, fewer than the " + std::to_string(parameters) +
         " parameters of one full-covariance Gaussian in d = " + std::to_string(d) +
         " (unregularised EM would fit noise)";
}

// em_for[terrain]: whether the EM baseline runs for that terrain setting (asked for, and every
// command has enough training samples in every fold; else the reason goes to *summary).
std::array<bool, 2> EmRowsToRun(const SampleSet& set, const std::vector<std::vector<int>>& fold_of,
                                const CvOptions& options, CvSummary* summary) {
  std::array<bool, 2> em_for = {false, false};
  if (!options.em_baseline) return em_for;
  for (bool terrain : {false, true}) {
    if (terrain ? !(options.with_terrain && summary->has_terrain) : !options.without_terrain) {
      continue;
    }
    const int d = set.pose_dim() + (terrain ? set.terrain_dim() : 0);
    std::string& why =
        terrain ? summary->em_with_terrain_omitted : summary->em_without_terrain_omitted;
    why = EmUnderdetermined(set, fold_of, options.folds, d);
    em_for[terrain] = why.empty();
  }
  return em_for;
}

double SampleSd(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / (v.size() - 1));
}

}  // namespace

std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  std::uint64_t h = SplitMix64(seed);
  h = SplitMix64(h ^ a);
  h = SplitMix64(h ^ (b + 0x632be59bd9b4e019ULL));
  return SplitMix64(h ^ (c + 0x8cb92ba72f3d8dd7ULL));
}

std::vector<int> StratifiedFolds(const Eigen::VectorXi& command, int folds, std::mt19937_64& rng) {
  assert(folds >= 1);
  std::map<int, std::vector<int>> rows_of;  // ordered by command id: deterministic
  for (int i = 0; i < command.size(); ++i) rows_of[command(i)].push_back(i);
  std::vector<int> fold_of(command.size(), 0);
  int next = 0;
  for (auto& [c, rows] : rows_of) {
    std::shuffle(rows.begin(), rows.end(), rng);
    for (int i : rows) {
      fold_of[i] = next;
      next = (next + 1) % folds;
    }
  }
  return fold_of;
}

std::vector<int> EpisodeFolds(const Eigen::VectorXi& episode, int folds, std::mt19937_64& rng) {
  assert(folds >= 1);
  std::map<int, std::vector<int>> rows_of;  // ordered by episode id: deterministic
  for (int i = 0; i < episode.size(); ++i) rows_of[episode(i)].push_back(i);
  assert(static_cast<int>(rows_of.size()) >= folds);
  std::vector<const std::vector<int>*> order;
  for (const auto& [e, rows] : rows_of) order.push_back(&rows);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<int> fold_of(episode.size(), 0);
  std::vector<long long> size(folds, 0);
  for (const std::vector<int>* rows : order) {
    const int f = static_cast<int>(std::min_element(size.begin(), size.end()) - size.begin());
    for (int i : *rows) fold_of[i] = f;
    size[f] += static_cast<long long>(rows->size());
  }
  return fold_of;
}

bool CvOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  std::string dgmm_error;
  if (!dgmm.IsValid(&dgmm_error)) return fail(dgmm_error);
  if (folds < 0 || folds == 1) {
    return fail("folds must be >= 2 (or 0: chosen from the data), got " + std::to_string(folds));
  }
  if (repeats < 1) return fail("repeats must be >= 1, got " + std::to_string(repeats));
  if (!without_terrain && !with_terrain) return fail("nothing to evaluate (no terrain setting)");
  if (em_baseline) {
    if (em_max_components < 1) return fail("em_max_components must be >= 1");
    std::string em_error;
    if (!em.IsValid(&em_error)) return fail(em_error);
  }
  if (threads < 0) return fail("threads must be >= 0");
  return true;
}

Mixture FitEmByBic(const Eigen::MatrixXd& Y, const EmOptions& em, int max_components,
                   int* components) {
  const int n = static_cast<int>(Y.rows()), d = static_cast<int>(Y.cols());
  std::optional<EmResult> best;
  int best_k = 0;
  for (int k = 1; k <= max_components && k <= n; ++k) {
    if (k > 1 && MixtureParameterCount(k, d) > n) break;
    EmOptions options = em;
    options.components = k;
    EmResult fit = FitEm(Y, options);
    if (!std::isfinite(fit.summary.bic)) continue;
    if (!best || fit.summary.bic < best->summary.bic) {
      best = std::move(fit);
      best_k = k;
    }
  }
  if (!best) {  // every fit degenerate: fall back to one component
    EmOptions options = em;
    options.components = 1;
    best = FitEm(Y, options);
    best_k = 1;
  }
  if (components) *components = best_k;
  return std::move(best->mixture);
}

namespace {

// One repeat's share of a terrain change: the paired differences of the per-sample held-out
// log-likelihoods with and without terrain (the same samples in the same order).
void AddTerrainChange(const std::vector<double>& with, const std::vector<double>& without, int repeats,
                      CvTerrainChange* change) {
  if (with.empty() || with.size() != without.size()) return;
  std::vector<double> d(with.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = with[i] - without[i];
  change->evaluated = true;
  change->mean += std::accumulate(d.begin(), d.end(), 0.0) / repeats;
  change->standard_error += std::sqrt(static_cast<double>(d.size())) * SampleSd(d) / repeats;
}

}  // namespace

namespace {

// Every (repeat, fold) task on the worker threads; results in task order (repeat-major).
std::vector<FoldResult> RunFolds(const SampleSet& set, const std::vector<std::vector<int>>& fold_of, int folds,
                                 const CvOptions& options, bool has_terrain, const std::array<bool, 2>& em_for) {
  const int tasks = options.repeats * folds;
  std::vector<FoldResult> results(tasks);
  std::mutex mutex;
  int done = 0;
  const int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  ParallelFor(tasks, threads, [&](int t) {
    results[t] = RunFold(set, fold_of[t / folds], t / folds, t % folds, options, has_terrain, em_for);
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (options.progress) options.progress(done, tasks);
  });
  return results;
}

// The rows, their standard errors and the terrain changes from the fold results, reduced in task
// order: the figures do not depend on the number of threads.
void Reduce(const std::vector<FoldResult>& results, int repeats, int folds, CvSummary* summary) {
  std::array<CvScore*, kVariants> scores = {&summary->dgmm_without_terrain, &summary->dgmm_with_terrain,
                                            &summary->em_without_terrain, &summary->em_with_terrain};
  double components_total[kVariants] = {0, 0, 0, 0};
  int em_commands = 0, dgmm_commands = 0;
  for (int v = 0; v < kVariants; ++v) scores[v]->per_fold = Eigen::MatrixXd::Zero(repeats, folds);
  for (int r = 0; r < repeats; ++r) {
    std::array<std::vector<double>, kVariants> all;
    int unscored = 0;
    for (int f = 0; f < folds; ++f) {
      const FoldResult& fr = results[r * folds + f];
      unscored += fr.unscored;
      em_commands += fr.em_commands;
      dgmm_commands += fr.dgmm_commands;
      for (int v = 0; v < kVariants; ++v) {
        scores[v]->per_fold(r, f) = std::accumulate(fr.per_sample[v].begin(), fr.per_sample[v].end(), 0.0);
        all[v].insert(all[v].end(), fr.per_sample[v].begin(), fr.per_sample[v].end());
        components_total[v] += fr.components[v];
      }
    }
    summary->unscored_per_repeat = unscored;
    AddTerrainChange(all[kDgmmWith], all[kDgmmWithout], repeats, &summary->dgmm_terrain_change);
    AddTerrainChange(all[kEmWith], all[kEmWithout], repeats, &summary->em_terrain_change);
    for (int v = 0; v < kVariants; ++v) {
      if (all[v].empty()) continue;
      scores[v]->evaluated = true;
      scores[v]->per_repeat.push_back(scores[v]->per_fold.row(r).sum());
      scores[v]->standard_error += std::sqrt(static_cast<double>(all[v].size())) * SampleSd(all[v]) / repeats;
      summary->scored_per_repeat = static_cast<int>(all[v].size());
    }
  }
  for (int v = 0; v < kVariants; ++v) {
    CvScore& s = *scores[v];
    if (!s.evaluated) continue;
    s.mean = std::accumulate(s.per_repeat.begin(), s.per_repeat.end(), 0.0) / s.per_repeat.size();
    s.sd = SampleSd(s.per_repeat);
    s.mean_per_sample = summary->scored_per_repeat > 0 ? s.mean / summary->scored_per_repeat : 0;
    const int commands = v >= kEmWithout ? em_commands : dgmm_commands;
    if (commands > 0) s.mean_components = components_total[v] / commands;
  }
}

}  // namespace

CvSummary CrossValidate(const SampleSet& set, const CvOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "cross-validation", error);
  if (set.size() == 0) throw MakeInputError("", "sample set", "is empty");
  const std::string problem = set.Validate();
  if (!problem.empty()) throw MakeInputError("", "sample set", problem);
  const auto start = std::chrono::steady_clock::now();

  CvSummary summary;
  summary.samples = set.size();
  summary.repeats = options.repeats;
  summary.has_terrain = set.terrain_dim() > 0;
  std::vector<int> distinct(set.command.data(), set.command.data() + set.size());
  std::sort(distinct.begin(), distinct.end());
  summary.commands = static_cast<int>(std::unique(distinct.begin(), distinct.end()) - distinct.begin());

  // Fold assignments first (serially), then every (repeat, fold) task on the worker threads.
  const FoldPlan plan = ChooseFolds(set, options.folds, options.group_by_episode);
  summary.folds = plan.folds;
  summary.folds_by = plan.reason;
  CvOptions planned = options;
  planned.folds = plan.folds;
  std::vector<std::vector<int>> fold_of(options.repeats);
  for (int r = 0; r < options.repeats; ++r) {
    std::mt19937_64 rng(DeriveSeed(options.seed, r, 0, 0));
    fold_of[r] = plan.by_episode ? EpisodeFolds(set.episode, planned.folds, rng)
                                 : StratifiedFolds(set.command, planned.folds, rng);
  }
  const std::array<bool, 2> em_for = EmRowsToRun(set, fold_of, planned, &summary);
  const std::vector<FoldResult> results = RunFolds(set, fold_of, planned.folds, options, summary.has_terrain, em_for);
  Reduce(results, options.repeats, planned.folds, &summary);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

std::string CvSummary::BriefReport() const {
  std::ostringstream out;
  out << repeats << " x " << folds << "-fold cross-validation, " << samples << " samples, "
      << commands << " commands, folds " << folds_by;
  auto row = [&](const char* name, const CvScore& s) {
    if (s.evaluated) out << "; " << name << " " << s.mean << " +- " << s.sd;
  };
  row("DGMM without terrain", dgmm_without_terrain);
  row("DGMM with terrain", dgmm_with_terrain);
  row("EM-BIC without terrain", em_without_terrain);
  row("EM-BIC with terrain", em_with_terrain);
  if (!em_without_terrain_omitted.empty()) {
    out << "; EM-BIC without terrain omitted: " << em_without_terrain_omitted;
  }
  if (!em_with_terrain_omitted.empty())
    out << "; EM-BIC with terrain omitted: " << em_with_terrain_omitted;
  return out.str();
}

}  // namespace dgmm
