#include "sim2real/verdict_stage.h"

#include <algorithm>
#include <set>

#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

int PositionIn(const std::vector<int>& v, int e) { return static_cast<int>(std::find(v.begin(), v.end(), e) - v.begin()); }

// Selected candidates by importance (the final selection's order is the order of selection).
std::vector<int> ByImportance(const SelectionResult& sel) {
  std::vector<int> order(sel.selected.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return sel.importance[a] > sel.importance[b]; });
  std::vector<int> out;
  for (int k : order) out.push_back(sel.selected[k]);
  return out;
}

int DriftPosition(const Adequacy& a, int k) {
  for (size_t q = 0; q < a.drift_tests.size(); ++q) {
    if (a.drift_tests[q].candidate == k && (a.drift_tests[q].drift.drifting || a.drift_tests[q].step_variation.drifting)) {
      return static_cast<int>(q);
    }
  }
  return -1;
}

VerdictNamed Named(const CandidateSet& set, const Refinement& r, const Confidence& confidence, const Adequacy& adequacy,
                   int k) {
  const KnobCandidate& c = set.candidates[k];
  const int pos = PositionIn(r.selection.selected, k);
  const KnobCheck& check = adequacy.checks[pos];
  VerdictNamed n;
  n.family = c.family, n.knob = c.knob, n.unit = c.unit, n.nominal = c.nominal;
  n.value = check.value, n.fitted = check.fitted;
  if (c.simulated) n.lo = c.lo, n.hi = c.hi;
  if (pos < static_cast<int>(confidence.value_lower.size())) {
    n.value_lower = confidence.value_lower[pos], n.value_upper = confidence.value_upper[pos];
  }
  for (const KnobRefinement& kr : r.refined) {
    if (kr.candidate == k) n.as_well = kr.as_well;
  }
  if (confidence.computed) {
    n.inclusion = std::clamp(confidence.family_inclusion.at(c.family), 0.0, 1.0);
    n.candidate_inclusion = confidence.inclusion[k];
    n.scope_inclusion = confidence.scope_inclusion[k];
  }
  const std::pair<bool, const char*> flags[] = {{check.pinned_low, "pinned_low"},     {check.pinned_high, "pinned_high"},
                                                {check.outside_range, "outside_range"}, {check.impossible, "impossible"},
                                                {check.unconverged, "unconverged"},
                                                {check.rugged, "not_single_peaked"},
                                                {check.chaotic, "chaotic_walk"}};
  for (const auto& [on, name] : flags) {
    if (on) n.flags.push_back(name);
  }
  n.doubts = check.doubts;
  return n;
}

// The doubt of a family the resamples hold but at two scopes: every servo's gain named where a
// side's gain was chosen in a quarter of them ("" when the named scope itself is held).
std::string ScopeDoubt(const CandidateSet& set, const Confidence& confidence, int k, double sure) {
  const KnobCandidate& c = set.candidates[k];
  if (!confidence.computed || confidence.family_inclusion.at(c.family) < sure || confidence.scope_inclusion[k] >= sure) {
    return "";
  }
  int other = -1;
  for (size_t o = 0; o < set.candidates.size(); ++o) {
    const KnobCandidate& d = set.candidates[o];
    if (d.family != c.family || d.WholeRobot() == c.WholeRobot()) continue;
    if (other < 0 || confidence.inclusion[o] > confidence.inclusion[other]) other = static_cast<int>(o);
  }
  if (other < 0) return "";
  const char* here = c.WholeRobot() ? "as the whole robot's knob" : "as a side's or a leg's knob";
  const char* there = c.WholeRobot() ? "as a side's or a leg's" : "as the whole robot's";
  return c.family + Fmt(" held in %.0f%% of the resamples, but ", 100 * confidence.family_inclusion.at(c.family)) + here +
         " (" + c.knob + Fmt(") in only %.0f%% and ", 100 * confidence.scope_inclusion[k]) + there + " (" +
         set.candidates[other].knob + Fmt(") in %.0f%%", 100 * confidence.scope_inclusion[other]) +
         ": these data do not tell whether the whole robot or a part of it differs";
}

VerdictDrifting Drifting(const CandidateSet& set, const Refinement& r, const Confidence& confidence,
                         const EffectDriftTest& test) {
  const int k = test.candidate;
  const KnobCandidate& c = set.candidates[k];
  const Eigen::VectorXd& t = r.selection.fit.theta[PositionIn(r.selection.selected, k)];
  auto value_at = [&](const Eigen::VectorXd& theta) { return CandidateValue(set, r, k, theta); };
  VerdictDrifting w;
  w.family = c.family, w.knob = c.knob, w.unit = c.unit, w.value = value_at(t), w.nominal = c.nominal;
  w.inclusion = confidence.computed ? confidence.family_inclusion.at(c.family) : -1;
  const bool session = test.drift.drifting;
  const EffectDrift& e = session ? test.drift : test.step_variation;
  w.along = session ? "session order" : "execution index";
  w.gamma = e.gamma, w.p_value = e.p_value;
  if (session) {
    w.first = value_at(t * (1 - e.gamma / 2)), w.last = value_at(t * (1 + e.gamma / 2));
  } else {
    w.first = value_at(t * e.low), w.last = value_at(t * e.high);
    w.first_step = e.low_step, w.last_step = e.high_step;
  }
  return w;
}

}  // namespace

bool VerdictOptions::IsValid(std::string* error) const {
  if (!(min_inclusion >= 0 && min_inclusion <= 1) || !(sure_inclusion >= min_inclusion && sure_inclusion <= 1) ||
      !(noise_structure_p > 0 && noise_structure_p < 1)) {
    if (error) *error = "0 <= min_inclusion <= sure_inclusion <= 1 and 0 < noise_structure_p < 1";
    return false;
  }
  return true;
}

Naming DecideNamed(const CandidateSet& set, const Refinement& r, const Confidence& confidence, const Adequacy& adequacy,
                   const VerdictOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "verdict options", error);
  Naming out;
  for (const auto& w : adequacy.residual.structured_in) out.structured |= w == "step" || w == "periodic" || w == "tails";
  // Tracker noise is named only for a pure change of scale: not when the corrected residual still
  // has structure within placements, nor strong residual means by command or terrain.
  bool means_left = false;
  for (const auto& t : adequacy.residual.tests) {
    means_left |= (t.where == "command" || t.where == "terrain") && t.p_value < options.noise_structure_p;
  }
  std::set<std::string> families, drifting_knobs;
  for (int k : ByImportance(r.selection)) {
    const KnobCandidate& c = set.candidates[k];
    if (families.count(c.family)) continue;
    if (c.family == "tracker_noise" && (out.structured || means_left)) {
      out.noise_withheld = true;
      continue;
    }
    if (c.family == "tracker_noise" && r.spread.tested && !r.spread.tracker_needed) {
      out.spread_from_knobs = true;
      continue;
    }
    const int q = DriftPosition(adequacy, k);
    if (q >= 0) {
      if (drifting_knobs.insert(c.knob).second) out.drifting.push_back(q);
      continue;
    }
    if (confidence.computed && confidence.family_inclusion.at(c.family) < options.min_inclusion) {
      out.weak.push_back(k);
      continue;
    }
    families.insert(c.family);
    out.named.push_back(k);
  }
  return out;
}

Verdict ComposeVerdict(const Baseline& base, const CandidateSet& set, const Refinement& r, const Confidence& confidence,
                       const Adequacy& adequacy, const Naming& naming, const TieResult& ties,
                       const VerdictOptions& options) {
  Verdict v;
  v.uneven_ground = base.permute_placements;
  v.gap_closed = adequacy.gap_closed;
  v.min_inclusion = confidence.computed ? options.min_inclusion : 0;
  for (int k : naming.named) {
    v.named.push_back(Named(set, r, confidence, adequacy, k));
    for (const auto& t : ties.ties) {
      if (t.candidate == k) v.named.back().tie_group = static_cast<int>(v.ties.size()), v.ties.push_back(t.tie);
    }
    for (const auto& d : v.named.back().doubts) v.doubts.push_back(d);
  }
  for (int q : naming.drifting) v.drifting.push_back(Drifting(set, r, confidence, adequacy.drift_tests[q]));
  for (int k : naming.weak) {
    const int pos = PositionIn(r.selection.selected, k);
    v.weak.push_back({set.candidates[k].family, set.candidates[k].knob, adequacy.checks[pos].value,
                      confidence.family_inclusion.at(set.candidates[k].family)});
  }
  for (const auto& d : adequacy.doubts) v.doubts.push_back(d);
  for (const VerdictNamed& n : v.named) {
    if (n.inclusion < 0 || n.inclusion >= options.sure_inclusion) continue;
    v.doubts.push_back(n.family + " (" + n.knob + Fmt(") held in %.0f%% of the resamples, under ", 100 * n.inclusion) +
                       Fmt("%.0f%%: these data are often read otherwise", 100 * options.sure_inclusion));
  }
  for (int k : naming.named) {
    const std::string doubt = ScopeDoubt(set, confidence, k, options.sure_inclusion);
    if (!doubt.empty()) v.doubts.push_back(doubt);
  }
  v.structured_in = adequacy.residual.structured_in;
  const bool session_drift = adequacy.total_drift.drifting, step_varies = adequacy.total_step_variation.drifting;
  if (session_drift) AddUnique(&v.structured_in, "session order");
  if (step_varies) AddUnique(&v.structured_in, "step");
  for (const auto& g : adequacy.remaining) AddUnique(&v.structured_in, g.label);
  if (naming.noise_withheld && v.structured_in.empty()) v.structured_in = {"command or terrain means"};
  v.unexplained_present = naming.structured || naming.noise_withheld || session_drift || step_varies ||
                          !adequacy.doubts.empty();
  if (v.named.empty()) {
    // A real-trained model that beats the sim model on held-out placements is a mismatch even where
    // no region test places it (rough ground: a region needs several placements a side); so is a knob
    // that forward selection took (it improved the held-out fit) but the resamples did not agree on.
    const bool mismatch = base.significant_mismatch || naming.structured || session_drift || step_varies ||
                          adequacy.below_ceiling || !v.weak.empty();
    v.status = mismatch ? "unexplained" : "clean";
    v.unexplained_present = mismatch;
    if (mismatch && v.structured_in.empty()) {
      for (const auto& g : base.before.significant) AddUnique(&v.structured_in, g.label);
      if (v.structured_in.empty()) {
        v.structured_in = {base.significant_mismatch ? "located regions"
                           : adequacy.below_ceiling  ? "the fit as a whole (below the real-trained ceiling)"
                                                     : "the fit as a whole (a knob improves the held-out fit)"};
      }
    }
  } else {
    v.status = v.unexplained_present || !v.doubts.empty() ? "partly_explained" : "explained";
  }
  v.sentence = VerdictSentence(v, &adequacy, &naming, &r);
  return v;
}

Verdict LocateOnlyVerdict(const Baseline& base, const std::string& why) {
  Verdict v;
  v.gap_closed = NAN;
  v.status = base.significant_mismatch ? "located" : "clean";
  v.unexplained_present = base.significant_mismatch;
  for (const auto& g : base.before.significant) AddUnique(&v.structured_in, g.label);
  v.doubts.push_back(why);
  v.sentence = VerdictSentence(v, nullptr, nullptr, nullptr);
  return v;
}

}  // namespace dgmm::sim2real
