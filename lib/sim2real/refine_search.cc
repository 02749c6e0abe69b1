#include "sim2real/refine_search.h"

#include <algorithm>

namespace dgmm::sim2real {

double FaceValueScore(const AnalysisInputs& in, const Baseline& base, CandidateSet* set, const Refinement& r, int k,
                      const std::vector<int>& shifts, const std::vector<int>& skip, const RefineOptions& options) {
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
  if (others.empty()) return CorrectedLogLikelihood(trial, EffectFit{}).sum();
  return FitEffects(trial, others, {}, options.selection.fit).train_log_likelihood;
}

}  // namespace dgmm::sim2real
