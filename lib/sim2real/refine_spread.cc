// The spread part of stage 4 (refine.h, spread.h).
#include <algorithm>

#include "sim2real/refine.h"

namespace dgmm::sim2real {
namespace {

// T and the range of a = (s^2 - 1) / (s_sig^2 - 1) for a tracker signature recorded at s_sig.
void SetTrackerSignature(const PairedShift& shift, double s_sig, const Knob& knob, SpreadProblem* sp) {
  sp->tracker = (shift.log_variance_ratio().array().exp() - 1).cwiseMax(0).matrix();
  const double den = s_sig * s_sig - 1;
  sp->a_lo = std::min((knob.lo * knob.lo - 1) / den, (knob.hi * knob.hi - 1) / den);
  sp->a_hi = std::max((knob.lo * knob.lo - 1) / den, (knob.hi * knob.hi - 1) / den);
}

double ScaleAt(double s_sig, double a) { return std::sqrt(std::max(0.0, 1 + a * (s_sig * s_sig - 1))); }

}  // namespace

void RefineTrackerSpread(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                         const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set,
                         Refinement* r) {
  const auto noise = std::find_if(set->candidates.begin(), set->candidates.end(),
                                  [](const KnobCandidate& c) { return c.key == "tracker_noise"; });
  const int noise_k = static_cast<int>(noise - set->candidates.begin());
  const SelectionResult& sel = r->selection;
  if (set->tracker_shift < 0 || noise == set->candidates.end() ||
      std::find(sel.selected.begin(), sel.selected.end(), noise_k) == sel.selected.end()) {
    return;
  }
  const Knob& knob = simulator.knobs()[set->tracker_knob];
  SpreadProblem sp;
  sp.fit = &r->problem;
  sp.log_var.assign(set->library.size(), Eigen::VectorXd());
  for (size_t k = 0; k < set->library.size(); ++k) sp.log_var[k] = CandidateLogVariance(*set, static_cast<int>(k));
  SetTrackerSignature(set->shifts[set->tracker_shift], set->tracker_probe, knob, &sp);
  std::vector<int> mean;
  for (int e : sel.selected) {
    if (e != noise_k) mean.push_back(e);
  }
  // The bar the noise scale cleared to be selected (its forward step's Bonferroni z), now against
  // the knobs' own spread rather than the sim model's.
  SpreadOptions spread_options = options.spread;
  for (const auto& step : sel.steps) {
    if (step.chosen == noise_k) spread_options.z = std::max(spread_options.z, step.threshold_z);
  }
  r->spread = TestTrackerSpread(sp, mean, r->rows, base.fold, options.selection.fit, spread_options);
  if (!r->spread.tracker_needed) return;
  const EffectFit fit = mean.empty() ? EffectFit{} : FitEffects(r->problem, mean, {}, options.selection.fit);
  const Eigen::VectorXd k = KnobSpread(sp, fit, options.spread);
  double s_sig = set->tracker_probe, a = r->spread.a;
  double best_sig = s_sig, best_a = a;
  r->trace.push_back({knob.name, s_sig, a});
  for (int it = 0; it < options.refine_iterations && std::abs(best_a - 1) >= options.converged_within; ++it) {
    const double s = std::clamp(ScaleAt(s_sig, a), knob.lo, knob.hi);
    if (std::abs(s * s - 1) < 0.05) break;  // no tracker signature can be recorded that close to nominal
    const PairedShift shift =
        RecordShift(simulator, in, *set, {KnobValue{set->tracker_knob, s}}, recording, &r->recorded, &r->from_cache);
    SetTrackerSignature(shift, s, knob, &sp);
    s_sig = s;
    a = FitTrackerCoefficient(sp, fit, k, sp.tracker, r->rows);
    r->trace.push_back({knob.name, s_sig, a});
    if (std::abs(a - 1) < std::abs(best_a - 1)) best_sig = s_sig, best_a = a;
  }
  r->tracker_scale = ScaleAt(best_sig, best_a);
  r->refined.push_back({noise_k, knob.name, r->tracker_scale, best_a, std::abs(best_a - 1) < options.converged_within,
                        best_sig != set->tracker_probe});
}

}  // namespace dgmm::sim2real
