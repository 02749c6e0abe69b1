#include "sim2real/refine.h"

#include <algorithm>
#include <chrono>

#include "util/error.h"

namespace dgmm::sim2real {
namespace {

int PositionIn(const std::vector<int>& v, int e) {
  return static_cast<int>(std::find(v.begin(), v.end(), e) - v.begin());
}

// The most important selected one-parameter knob not yet searched (-1: none); `done` holds knob indices.
int NextToRefine(const SelectionResult& sel, const CandidateSet& set, const std::vector<int>& done) {
  int top = -1;
  double top_importance = -INFINITY;
  for (size_t k = 0; k < sel.selected.size(); ++k) {
    const int e = sel.selected[k];
    const int knob = set.candidates[e].knob_index;
    if (knob >= 0 && PositionIn(done, knob) == static_cast<int>(done.size()) &&
        sel.importance[k] > top_importance) {
      top = e, top_importance = sel.importance[k];
    }
  }
  return top;
}

void RefineKnobs(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                 const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set, Refinement* r) {
  std::vector<int> done;
  for (int round = 0; round < options.refine_knobs && options.refine_iterations > 0; ++round) {
    const int top = NextToRefine(r->selection, *set, done);
    if (top < 0) break;
    done.push_back(set->candidates[top].knob_index);
    const double a0 = r->selection.fit.theta[PositionIn(r->selection.selected, top)](0);
    SearchKnob(simulator, in, base, recording, options, set, r, top, a0);
  }
}

}  // namespace

bool RefineOptions::IsValid(std::string* error) const {
  if (refine_iterations < 0 || refine_knobs < 0 || payload_rounds < 0 || !(converged_within > 0) ||
      !(payload_contender_share > 0 && payload_contender_share <= 1) || !(as_well_z > 0) ||
      !(payload_middle_line_z > 0)) {
    if (error) {
      *error = "refine_iterations >= 0, refine_knobs >= 0, payload_rounds >= 0, converged_within > 0, "
               "payload_contender_share in (0, 1], as_well_z > 0, payload_middle_line_z > 0";
    }
    return false;
  }
  return selection.IsValid(error) && spread.IsValid(error);
}

namespace {

// The value of a candidate whose signature was recorded at `at`: a searched one's is `at` itself,
// the recording that scored best taken at face value, and a refit (a bootstrap resample's) scales
// its deviation by the coefficient relative to the final fit's; otherwise the linear reading
// nominal + theta (at - nominal).
double SearchedValue(const Refinement& r, int k, double nominal, double at, const Eigen::VectorXd& theta) {
  const auto& sel = r.selection.selected;
  const auto pos = std::find(sel.begin(), sel.end(), k);
  if (k < static_cast<int>(r.searched.size()) && r.searched[k] && pos != sel.end()) {
    const double full = r.selection.fit.theta[pos - sel.begin()](0);
    if (full > 0) return nominal + (at - nominal) * theta(0) / full;
  }
  return nominal + theta(0) * (at - nominal);
}

}  // namespace

double CandidateValue(const CandidateSet& set, const Refinement& r, int k, const Eigen::VectorXd& theta) {
  const KnobCandidate& c = set.candidates[k];
  if (c.key == "payload") {
    return SearchedValue(r, k, c.nominal, std::isfinite(r.payload_mass) ? r.payload_mass : c.probe, theta);
  }
  if (c.knob_index >= 0) return SearchedValue(r, k, c.nominal, r.signature_at[k], theta);
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
  out.searched.assign(set->candidates.size(), false);
  out.selection_options = options.selection;
  out.selection_options.backward = true;
  out.selection = ForwardSelect(out.problem, out.rows, base.fold, out.selection_options);
  RefinePayload(simulator, in, base, recording, options, set, &out);
  RefineKnobs(simulator, in, base, recording, options, set, &out);
  RefineTrackerSpread(simulator, in, base, recording, options, set, &out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace dgmm::sim2real
