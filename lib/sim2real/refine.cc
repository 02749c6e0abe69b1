#include "sim2real/refine.h"

#include <algorithm>
#include <chrono>

#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// What every refinement needs besides its own knob.
struct RefineContext {
  const KnobSimulator& simulator;
  const AnalysisInputs& in;
  const Baseline& base;
  const CandidateOptions& recording;
  const RefineOptions& options;
  CandidateSet* set;
  Refinement* out;
  // Records the sim set at the values and appends its paired shift; returns its index.
  int Record(const std::vector<KnobValue>& values) const {
    set->shifts.push_back(RecordShift(simulator, in, *set, values, recording, &out->recorded, &out->from_cache));
    return static_cast<int>(set->shifts.size()) - 1;
  }
  SelectionOptions Selection() const {
    SelectionOptions s = options.selection;
    s.backward = true;
    return s;
  }
  void Reselect() const { out->selection = ForwardSelect(out->problem, out->rows, base.fold, Selection()); }
};

// The next value to record when refining a knob towards coefficient 1, from the (value,
// coefficient) pairs recorded so far and the last one (`value`, coefficient `a`): inside a
// bracket (one coefficient above 1, one below) the linear interpolation of the coefficient to 1
// (regula falsi); otherwise the secant step nominal + a (value - nominal). Clamped to [lo, hi].
double NextRefineValue(const std::vector<std::pair<double, double>>& trace, double nominal, double value, double a,
                       double lo, double hi) {
  double lo_v = NAN, lo_a = 0, hi_v = NAN, hi_a = 0;
  for (const auto& [tv, ta] : trace) {
    if (ta > 1 && (!std::isfinite(lo_v) || ta < lo_a)) lo_v = tv, lo_a = ta;
    if (ta < 1 && (!std::isfinite(hi_v) || ta > hi_a)) hi_v = tv, hi_a = ta;
  }
  const double next = std::isfinite(lo_v) && std::isfinite(hi_v) ? lo_v + (1 - lo_a) * (hi_v - lo_v) / (hi_a - lo_a)
                                                                 : nominal + a * (value - nominal);
  return std::clamp(next, lo, hi);
}

int PositionIn(const std::vector<int>& v, int e) {
  return static_cast<int>(std::find(v.begin(), v.end(), e) - v.begin());
}

// The secant / regula-falsi loop refining one-parameter knob candidate k from `start`, its
// probe's coefficient `first_coefficient`: each step records the knob at a value and refits; the
// best signature (|coefficient - 1| smallest, the probe's included) is kept.
KnobRefinement RefineLoop(const RefineContext& ctx, int k, double start, double first_coefficient) {
  const KnobCandidate& c = ctx.set->candidates[k];
  const int pos = PositionIn(ctx.out->selection.selected, k);
  std::vector<std::pair<double, double>> trace = {{c.probe, first_coefficient}};
  KnobRefinement r{k, c.knob, c.probe, first_coefficient, false};
  double best_err = std::abs(first_coefficient - 1);
  std::vector<int> best_shifts = ctx.set->externals[k].shifts;
  double value = start;
  FitProblem trial = ctx.out->problem;
  for (int it = 0; it < ctx.options.refine_iterations && best_err >= ctx.options.converged_within; ++it) {
    if (std::abs(value - c.nominal) < 1e-9 * (1 + std::abs(c.nominal))) break;
    ctx.set->externals[k].shifts = {ctx.Record({KnobValue{c.knob_index, value}})};
    FillCandidateDesign(ctx.in, ctx.base, *ctx.set, k, &trial);
    const double a = FitEffects(trial, ctx.out->selection.selected, {}, ctx.options.selection.fit).theta[pos](0);
    trace.emplace_back(value, a);
    ctx.out->trace.push_back({c.knob, value, a});
    if (std::abs(a - 1) < best_err) {
      best_err = std::abs(a - 1);
      best_shifts = ctx.set->externals[k].shifts;
      r.value = value, r.coefficient = a, r.recorded = true;
    }
    value = NextRefineValue(trace, c.nominal, value, a, c.lo, c.hi);
  }
  ctx.set->externals[k].shifts = best_shifts;
  r.converged = best_err < ctx.options.converged_within;
  return r;
}

// The most important selected one-parameter knob not yet refined (-1: none).
int NextToRefine(const SelectionResult& sel, const CandidateSet& set, const std::vector<int>& done) {
  int top = -1;
  double top_importance = -INFINITY;
  for (size_t k = 0; k < sel.selected.size(); ++k) {
    const int e = sel.selected[k];
    if (set.candidates[e].knob_index >= 0 && PositionIn(done, e) == static_cast<int>(done.size()) &&
        sel.importance[k] > top_importance) {
      top = e, top_importance = sel.importance[k];
    }
  }
  return top;
}

void RefineKnobs(const RefineContext& ctx) {
  std::vector<int> done;
  for (int round = 0; round < ctx.options.refine_knobs && ctx.options.refine_iterations > 0; ++round) {
    const int top = NextToRefine(ctx.out->selection, *ctx.set, done);
    if (top < 0) break;
    done.push_back(top);
    const KnobCandidate& c = ctx.set->candidates[top];
    const int pos = PositionIn(ctx.out->selection.selected, top);
    const double a0 = ctx.out->selection.fit.theta[pos](0);
    ctx.out->trace.push_back({c.knob, c.probe, a0});
    const double start = std::clamp(c.nominal + a0 * (c.probe - c.nominal), c.lo, c.hi);
    const KnobRefinement r = RefineLoop(ctx, top, start, a0);
    ctx.out->refined.push_back(r);
    if (!r.recorded) continue;  // the probe's signature was already the best
    ctx.out->signature_at[top] = r.value;
    FillCandidateDesign(ctx.in, ctx.base, *ctx.set, top, &ctx.out->problem);
    ctx.Reselect();
  }
}

}  // namespace

bool RefineOptions::IsValid(std::string* error) const {
  if (refine_iterations < 0 || refine_knobs < 0 || !(converged_within > 0) ||
      !(payload_contender_share > 0 && payload_contender_share <= 1)) {
    if (error) *error = "refine_iterations >= 0, refine_knobs >= 0, converged_within > 0, payload_contender_share in (0, 1]";
    return false;
  }
  return selection.IsValid(error) && spread.IsValid(error);
}

double CandidateValue(const CandidateSet& set, const Refinement& r, int k, const Eigen::VectorXd& theta) {
  const KnobCandidate& c = set.candidates[k];
  if (c.key == "payload") {
    const double at = std::isfinite(r.payload_mass) ? r.payload_mass : c.probe;
    // A searched payload's value is the mass whose recording scored best, taken at face value; a
    // refit (a bootstrap resample's) scales it by its coefficient relative to the final fit's.
    const auto& sel = r.selection.selected;
    const auto pos = std::find(sel.begin(), sel.end(), k);
    if (r.payload_searched && pos != sel.end()) {
      const double full = r.selection.fit.theta[pos - sel.begin()](0);
      if (full > 0) return c.nominal + (at - c.nominal) * theta(0) / full;
    }
    return c.nominal + theta(0) * (at - c.nominal);
  }
  if (c.knob_index >= 0) return c.nominal + theta(0) * (r.signature_at[k] - c.nominal);
  if (c.family == "tracker_noise") return std::isfinite(r.tracker_scale) ? r.tracker_scale : std::exp(theta(0));
  return theta.cwiseAbs().maxCoeff() * (c.family == "heading_drift" && theta(0) < 0 ? -1 : 1);
}

Refinement SelectAndRefine(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                           const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "refinement options", error);
  const auto start = std::chrono::steady_clock::now();
  Refinement out;
  out.problem = MakeCandidateProblem(in, base, *set);
  out.rows.resize(in.real.size());
  for (int i = 0; i < in.real.size(); ++i) out.rows[i] = i;
  out.signature_at.assign(set->candidates.size(), NAN);
  for (size_t k = 0; k < set->candidates.size(); ++k) {
    if (set->candidates[k].knob_index >= 0) out.signature_at[k] = set->candidates[k].probe;
  }
  const RefineContext ctx{simulator, in, base, recording, options, set, &out};
  out.selection_options = ctx.Selection();
  ctx.Reselect();
  RefinePayload(simulator, in, base, recording, options, set, &out);
  RefineKnobs(ctx);
  RefineTrackerSpread(ctx.simulator, in, base, recording, options, set, &out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace dgmm::sim2real
