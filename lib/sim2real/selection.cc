#include "sim2real/selection.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

namespace dgmm::sim2real {

double UpperQuantile(double p) {
  double lo = -10, hi = 10;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

const CandidateScore* FirstStepBest(const SelectionResult& selection) {
  if (selection.steps.empty() || selection.steps[0].candidates.empty()) return nullptr;
  const std::vector<CandidateScore>& c = selection.steps[0].candidates;
  return &*std::max_element(c.begin(), c.end(), [](const CandidateScore& x, const CandidateScore& y) { return x.z < y.z; });
}

namespace {

double Correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double na = a.norm(), nb = b.norm();
  if (na < 1e-300 || nb < 1e-300) return 0.0;
  return a.dot(b) / (na * nb);  // uncentred: shifts are measured from the sim prediction
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const size_t i = static_cast<size_t>(pos);
  const double f = pos - i;
  return i + 1 < v.size() ? (1 - f) * v[i] + f * v[i + 1] : v[i];
}

// Whether effect a's mean shifts are a special case of effect b's on these samples: every
// whitened design column of a lies in the column space of b's (relative residual < 1e-6).
bool NestedIn(const FitProblem& fp, int a, int b) {
  if (a == b || fp.library[a].is_noise || fp.library[b].is_noise) return false;
  const Eigen::MatrixXd& ga = fp.g[a];
  const Eigen::MatrixXd& gb = fp.g[b];
  if (ga.cols() == 0 || gb.cols() <= ga.cols() || ga.norm() < 1e-300) return false;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(gb);
  const Eigen::MatrixXd residual = ga - gb * qr.solve(ga);
  return residual.norm() < 1e-6 * ga.norm();
}

}  // namespace

bool SelectionOptions::IsValid(std::string* error) const {
  if (folds < 2 || !(alpha > 0 && alpha < 1) || max_effects < 0 || bootstrap_selection < 0 ||
      bootstrap_parameters < 0 || !(confusion_correlation > 0 && confusion_correlation <= 1)) {
    if (error) *error = "folds >= 2, 0 < alpha < 1, non-negative counts, 0 < correlation <= 1";
    return false;
  }
  return fit.IsValid(error);
}

std::vector<int> MakeFolds(const FitProblem& fp, const std::vector<int>& rows, int folds,
                           std::mt19937_64& rng) {
  return MakeFolds(fp.episode, fp.command, rows, folds, rng);
}

std::vector<int> MakeFolds(const std::vector<int>& episode, const std::vector<int>& command,
                           const std::vector<int>& rows, int folds, std::mt19937_64& rng) {
  // Episodes (by original id) per command, in order of first appearance, then shuffled.
  std::map<int, std::vector<int>> episodes_of_command;
  std::set<int> seen;
  for (int i : rows) {
    if (seen.insert(episode[i]).second) episodes_of_command[command[i]].push_back(episode[i]);
  }
  std::map<int, int> fold_of_episode;
  int offset = 0;
  for (auto& [c, eps] : episodes_of_command) {
    std::shuffle(eps.begin(), eps.end(), rng);
    for (size_t k = 0; k < eps.size(); ++k) fold_of_episode[eps[k]] = (offset + k) % folds;
    offset += static_cast<int>(eps.size());
  }
  std::vector<int> fold(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) fold[k] = fold_of_episode[episode[rows[k]]];
  return fold;
}

FoldSplit SplitFold(const std::vector<int>& rows, const std::vector<int>& fold, int f) {
  FoldSplit split;
  for (size_t k = 0; k < rows.size(); ++k) {
    if (fold[k] == f) {
      split.test.push_back(rows[k]);
      split.test_pos.push_back(static_cast<int>(k));
    } else {
      split.train.push_back(rows[k]);
    }
  }
  return split;
}

Eigen::VectorXd CrossValidate(const FitProblem& fp, const std::vector<int>& effects,
                              const std::vector<int>& rows, const std::vector<int>& fold,
                              const EffectFitOptions& options) {
  Eigen::VectorXd ll = Eigen::VectorXd::Zero(rows.size());
  const int folds = fold.empty() ? 0 : *std::max_element(fold.begin(), fold.end()) + 1;
  if (effects.empty()) return CorrectedLogLikelihood(fp, EffectFit{}, rows);
  for (int f = 0; f < folds; ++f) {
    const FoldSplit split = SplitFold(rows, fold, f);
    if (split.test.empty() || split.train.empty()) continue;
    EffectFit fit = FitEffects(fp, effects, split.train, options);
    Eigen::VectorXd t = CorrectedLogLikelihood(fp, fit, split.test);
    for (size_t k = 0; k < split.test.size(); ++k) ll(split.test_pos[k]) = t(k);
  }
  return ll;
}

void ClusteredMean(const Eigen::VectorXd& d, const std::vector<int>& cluster, double* mean,
                   double* se) {
  const double n = static_cast<double>(d.size());
  *mean = n > 0 ? d.mean() : 0.0;
  std::map<int, std::pair<double, int>> sums;
  for (int i = 0; i < d.size(); ++i) {
    sums[cluster[i]].first += d(i);
    sums[cluster[i]].second += 1;
  }
  const double g = static_cast<double>(sums.size());
  double v = 0;
  for (const auto& [c, s] : sums) v += std::pow(s.first - s.second * *mean, 2);
  *se = g > 1 ? std::sqrt(g / (g - 1) * v) / n : INFINITY;
}

namespace {

// What every step of the selection shares.
struct SelectionContext {
  const FitProblem& fp;
  const std::vector<int>& rows;
  const std::vector<int>& fold;
  const SelectionOptions& options;
  std::vector<int> cluster;  // episode per entry of rows (duplicated episodes share a cluster)
};

// Held-out gain of each remaining candidate added to `selected`, over `current`; sorted by gain.
SelectionStep ScoreCandidates(const SelectionContext& ctx, const std::vector<int>& selected,
                              const std::vector<int>& remaining, const Eigen::VectorXd& current,
                              std::map<int, Eigen::VectorXd>* heldout) {
  SelectionStep step;
  step.threshold_z = UpperQuantile(ctx.options.alpha / remaining.size());
  for (int e : remaining) {
    std::vector<int> trial = selected;
    trial.push_back(e);
    (*heldout)[e] = CrossValidate(ctx.fp, trial, ctx.rows, ctx.fold, ctx.options.fit);
    CandidateScore score;
    score.effect = e;
    ClusteredMean((*heldout)[e] - current, ctx.cluster, &score.gain, &score.se);
    score.z = score.se > 0 ? score.gain / score.se : 0.0;
    step.candidates.push_back(score);
  }
  std::sort(step.candidates.begin(), step.candidates.end(), [](const auto& a, const auto& b) { return a.gain > b.gain; });
  return step;
}

// The best-gaining candidate among those whose gain is significant (a larger but noisier gain does
// not stop a clearly significant one), or a significant one nested in it whose gain is within one
// clustered SE of the paired difference (the simpler explanation the data cannot beat); moved to
// the front. False: none is significant.
bool ChooseCandidate(const SelectionContext& ctx, const std::map<int, Eigen::VectorXd>& heldout, SelectionStep* step) {
  const auto significant = [&](const CandidateScore& c) {
    return c.z > step->threshold_z && c.gain > ctx.options.min_gain_nats;
  };
  auto eligible = std::find_if(step->candidates.begin(), step->candidates.end(), significant);
  if (eligible == step->candidates.end()) return false;
  for (auto it = step->candidates.begin(); it != step->candidates.end(); ++it) {
    if (it == eligible || !significant(*it) || !NestedIn(ctx.fp, it->effect, eligible->effect)) continue;
    double diff, diff_se;
    ClusteredMean(heldout.at(eligible->effect) - heldout.at(it->effect), ctx.cluster, &diff, &diff_se);
    if (diff <= diff_se && ctx.fp.library[it->effect].num_params() < ctx.fp.library[eligible->effect].num_params()) {
      eligible = it;
    }
  }
  std::iter_swap(step->candidates.begin(), eligible);  // keep the chosen one first
  std::stable_sort(step->candidates.begin() + 1, step->candidates.end(),
                   [](const auto& a, const auto& b) { return a.gain > b.gain; });
  step->chosen = step->candidates.front().effect;
  return true;
}

// Which runners-up the data cannot separate from the chosen one: near-equal held-out gain (within
// one clustered SE of the paired difference) and strongly correlated fitted shifts.
void MarkConfusable(const SelectionContext& ctx, const std::vector<int>& selected,
                    const std::map<int, Eigen::VectorXd>& heldout, const Eigen::VectorXd& current,
                    SelectionStep* step) {
  const FitProblem& fp = ctx.fp;
  const CandidateScore& best = step->candidates.front();
  std::vector<int> with_best = selected;
  with_best.push_back(best.effect);
  const EffectFit fit_best = FitEffects(fp, with_best, ctx.rows, ctx.options.fit);
  const Eigen::VectorXd shift_best = WhitenedShift(fp, fit_best, static_cast<int>(with_best.size()) - 1);
  for (size_t k = 1; k < step->candidates.size(); ++k) {
    const CandidateScore& other = step->candidates[k];
    double diff, diff_se;
    ClusteredMean(heldout.at(best.effect) - heldout.at(other.effect), ctx.cluster, &diff, &diff_se);
    if (diff > diff_se || other.gain <= 0) continue;
    std::vector<int> with_other = selected;
    with_other.push_back(other.effect);
    const EffectFit fit_other = FitEffects(fp, with_other, ctx.rows, ctx.options.fit);
    double corr;
    if (fp.library[best.effect].is_noise || fp.library[other.effect].is_noise) {
      const Eigen::VectorXd a = heldout.at(best.effect) - current, b = heldout.at(other.effect) - current;
      corr = Correlation(a.array() - a.mean(), b.array() - b.mean());
    } else {
      corr = Correlation(shift_best, WhitenedShift(fp, fit_other, static_cast<int>(with_other.size()) - 1));
    }
    if (std::abs(corr) >= ctx.options.confusion_correlation) step->confusable.push_back(other.effect);
  }
}

// Held-out log-likelihood of the selection without its k-th effect, per k.
std::vector<Eigen::VectorXd> HeldoutWithoutEach(const SelectionContext& ctx, const std::vector<int>& selected) {
  std::vector<Eigen::VectorXd> out;
  for (size_t k = 0; k < selected.size(); ++k) {
    std::vector<int> without = selected;
    without.erase(without.begin() + k);
    out.push_back(CrossValidate(ctx.fp, without, ctx.rows, ctx.fold, ctx.options.fit));
  }
  return out;
}

// Backward pass: drop the effect whose removal costs least while that cost is insignificant.
// Returns the held-out values without each remaining effect when computed for the final set.
std::vector<Eigen::VectorXd> BackwardPass(const SelectionContext& ctx, SelectionResult* result,
                                          Eigen::VectorXd* current) {
  std::vector<Eigen::VectorXd> without_ll;
  while (ctx.options.backward && result->selected.size() > 1) {
    const double threshold = UpperQuantile(ctx.options.alpha / result->selected.size());
    without_ll = HeldoutWithoutEach(ctx, result->selected);
    size_t weakest = 0;
    double weakest_z = INFINITY, weakest_gain = 0;
    for (size_t k = 0; k < result->selected.size(); ++k) {
      double gain, se;
      ClusteredMean(*current - without_ll[k], ctx.cluster, &gain, &se);
      const double z = se > 0 ? gain / se : (gain > 0 ? INFINITY : 0.0);
      if (z < weakest_z) weakest = k, weakest_z = z, weakest_gain = gain;
    }
    if (weakest_z > threshold && weakest_gain > ctx.options.min_gain_nats) break;
    result->removed.push_back(result->selected[weakest]);
    result->selected.erase(result->selected.begin() + weakest);
    *current = without_ll[weakest];
    without_ll.clear();
  }
  return without_ll;
}

}  // namespace

SelectionResult ForwardSelect(const FitProblem& fp, const std::vector<int>& rows,
                              const std::vector<int>& fold, const SelectionOptions& options) {
  SelectionContext ctx{fp, rows, fold, options, {}};
  for (int r : rows) ctx.cluster.push_back(fp.episode[r]);
  SelectionResult result;
  Eigen::VectorXd current = CrossValidate(fp, {}, rows, fold, options.fit);
  result.heldout_sim = current;
  std::vector<int> remaining(fp.library.size());
  std::iota(remaining.begin(), remaining.end(), 0);
  while (static_cast<int>(result.selected.size()) < options.max_effects && !remaining.empty()) {
    std::map<int, Eigen::VectorXd> heldout;
    SelectionStep step = ScoreCandidates(ctx, result.selected, remaining, current, &heldout);
    if (!ChooseCandidate(ctx, heldout, &step)) {
      result.steps.push_back(step);
      break;
    }
    MarkConfusable(ctx, result.selected, heldout, current, &step);
    result.selected.push_back(step.chosen);
    current = heldout[step.chosen];
    remaining.erase(std::find(remaining.begin(), remaining.end(), step.chosen));
    result.steps.push_back(step);
  }
  std::vector<Eigen::VectorXd> without_ll = BackwardPass(ctx, &result, &current);
  result.heldout_corrected = current;
  result.fit = FitEffects(fp, result.selected, rows, options.fit);
  if (result.selected.size() > 1 && without_ll.empty()) without_ll = HeldoutWithoutEach(ctx, result.selected);
  for (size_t k = 0; k < result.selected.size(); ++k) {
    const Eigen::VectorXd& reference = result.selected.size() == 1 ? result.heldout_sim : without_ll[k];
    result.importance.push_back((current - reference).mean());
  }
  return result;
}

BootstrapResult Bootstrap(const FitProblem& fp, const SelectionResult& selection,
                          const SelectionOptions& options, std::mt19937_64& rng) {
  BootstrapResult out;
  out.inclusion.assign(fp.library.size(), 0.0);
  std::map<int, std::vector<int>> rows_of_episode;
  for (int i = 0; i < fp.n; ++i) rows_of_episode[fp.episode[i]].push_back(i);
  std::vector<int> episodes;
  for (const auto& [e, r] : rows_of_episode) episodes.push_back(e);
  if (episodes.empty()) return out;
  std::uniform_int_distribution<size_t> pick(0, episodes.size() - 1);
  auto resample = [&]() {
    std::vector<int> rows;
    for (size_t k = 0; k < episodes.size(); ++k) {
      const auto& r = rows_of_episode[episodes[pick(rng)]];
      rows.insert(rows.end(), r.begin(), r.end());
    }
    return rows;
  };
  SelectionOptions quick = options;
  std::vector<int> count(fp.library.size(), 0);
  for (int b = 0; b < options.bootstrap_selection; ++b) {
    std::vector<int> rows = resample();
    std::vector<int> fold = MakeFolds(fp, rows, options.folds, rng);
    SelectionResult r = ForwardSelect(fp, rows, fold, quick);
    for (int e : r.selected) ++count[e];
    out.selections.push_back(r.selected);
  }
  for (size_t e = 0; e < count.size() && options.bootstrap_selection > 0; ++e) {
    out.inclusion[e] = static_cast<double>(count[e]) / options.bootstrap_selection;
  }
  const size_t k = selection.selected.size();
  std::vector<std::vector<std::vector<double>>> draws(k);
  for (size_t j = 0; j < k; ++j) draws[j].resize(selection.fit.theta[j].size());
  for (int b = 0; b < options.bootstrap_parameters; ++b) {
    EffectFit fit = FitEffects(fp, selection.selected, resample(), options.fit);
    for (size_t j = 0; j < k; ++j) {
      for (int q = 0; q < fit.theta[j].size(); ++q) draws[j][q].push_back(fit.theta[j](q));
    }
  }
  for (size_t j = 0; j < k; ++j) {
    const int p = static_cast<int>(selection.fit.theta[j].size());
    Eigen::VectorXd lo(p), hi(p);
    for (int q = 0; q < p; ++q) {
      lo(q) = Percentile(draws[j][q], 0.025);
      hi(q) = Percentile(draws[j][q], 0.975);
    }
    out.lower.push_back(lo);
    out.upper.push_back(hi);
  }
  return out;
}

}  // namespace dgmm::sim2real
