#include "sim2real/refine_search.h"

#include <algorithm>
#include <cmath>

#include "sim2real/sentence_format.h"
#include "sim2real/units.h"

namespace dgmm::sim2real {

double FaceValueScore(const AnalysisInputs& in, const Baseline& base, CandidateSet* set, const Refinement& r, int k,
                      const std::vector<int>& shifts, const std::vector<int>& skip, const RefineOptions& options,
                      Eigen::VectorXd* rows) {
  FitProblem trial = r.problem;
  const std::vector<int> keep = set->externals[k].shifts;
  set->externals[k].shifts = shifts;
  FillCandidateDesign(in, base, *set, k, &trial);
  set->externals[k].shifts = keep;
  for (int i = 0; i < trial.n; ++i) {
    trial.r0.row(i) -= trial.g[k].col(0).segment(i * trial.dx, trial.dx).transpose();
    trial.raw.row(i) -= trial.d[k].col(0).segment(i * trial.dx, trial.dx).transpose();
  }
  std::vector<int> others;
  for (int e : r.selection.selected) {
    if (e != k && std::find(skip.begin(), skip.end(), e) == skip.end()) others.push_back(e);
  }
  if (others.empty()) {
    const Eigen::VectorXd l = CorrectedLogLikelihood(trial, EffectFit{});
    if (rows) *rows = l;
    return l.sum();
  }
  const EffectFit fit = FitEffects(trial, others, {}, options.selection.fit);
  if (rows) *rows = CorrectedLogLikelihood(trial, fit);
  return fit.train_log_likelihood;
}

PairedSum PairedDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const UnitIds& placements) {
  PairedSum out;
  const int g = placements.count;
  if (a.size() != b.size() || g < 2) return out;
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(g);
  for (int i = 0; i < a.size(); ++i) sums(placements.unit[i]) += a(i) - b(i);
  out.sum = sums.sum();
  out.se = std::sqrt(g / (g - 1.0) * (sums.array() - out.sum / g).square().sum());
  return out;
}

bool FitsAsWellAs(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const UnitIds& placements, double z,
                  bool untold) {
  if (a.size() != b.size() || placements.count < 2) return untold;
  const PairedSum d = PairedDifference(a, b, placements);
  const double bar = z * d.se;
  return std::isnan(d.sum) || std::isnan(bar) ? untold : d.sum < bar;
}

std::vector<bool> FitAsWellAsTheBest(const std::vector<Eigen::VectorXd>& rows, int best,
                                     const std::vector<int>& placement, double z) {
  const UnitIds units = NumberUnits(placement);
  std::vector<bool> out(rows.size(), false);
  for (size_t k = 0; k < rows.size(); ++k) {
    out[k] = static_cast<int>(k) == best || FitsAsWellAs(rows[best], rows[k], units, z, false);
  }
  return out;
}

SearchSpan FitAsWellSpan(const std::vector<Eigen::VectorXd>& rows, int best, const std::vector<double>& values,
                         const std::vector<double>& x, const std::vector<int>& placement, double z) {
  const std::vector<bool> as_well = FitAsWellAsTheBest(rows, best, placement, z);
  SearchSpan span;
  span.z = z;
  span.searched = static_cast<int>(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!as_well[i]) continue;
    span.lower = std::fmin(span.lower, values[i]);
    span.upper = std::fmax(span.upper, values[i]);
    if (!x.empty()) span.x_lower = std::fmin(span.x_lower, x[i]), span.x_upper = std::fmax(span.x_upper, x[i]);
    ++span.points;
  }
  return span;
}

ScoreDip DeepestDip(const std::vector<Eigen::VectorXd>& rows, const std::vector<double>& values,
                    const std::vector<int>& placement, double z) {
  const UnitIds units = NumberUnits(placement);
  std::vector<int> order(rows.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return values[a] < values[b]; });
  std::vector<double> score(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) score[i] = rows[i].sum();
  auto by_score = [&](int a, int b) { return score[a] < score[b]; };
  auto best_of = [&](auto first, auto last) { return *std::max_element(first, last, by_score); };
  ScoreDip out;
  double depth = 0;
  for (size_t i = 1; i + 1 < order.size(); ++i) {
    const int at = order[i], left = best_of(order.begin(), order.begin() + i);
    const int right = best_of(order.begin() + i + 1, order.end());
    if (FitsAsWellAs(rows[left], rows[at], units, z, true) || FitsAsWellAs(rows[right], rows[at], units, z, true)) {
      continue;
    }
    const PairedSum below = PairedDifference(rows[left], rows[at], units);
    const PairedSum above = PairedDifference(rows[right], rows[at], units);
    if (std::min(below.sum, above.sum) <= depth) continue;
    out = {at, left, right, below, above};
    depth = std::min(below.sum, above.sum);
  }
  return out;
}

std::string DipDeficits(const ScoreDip& dip, int real_samples) {
  const double n = real_samples;
  auto z = [](const PairedSum& d) { return d.se > 0 ? d.sum / d.se : INFINITY; };
  return Fmt("(by %.2f and %.2f nats per real sample, ", dip.below.sum / n, dip.above.sum / n) +
         Fmt("z %.1f and %.1f)", z(dip.below), z(dip.above));
}

}  // namespace dgmm::sim2real
