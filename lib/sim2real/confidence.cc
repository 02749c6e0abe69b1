#include "sim2real/confidence.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>

namespace dgmm::sim2real {
namespace {

// A candidate's family at its scope: "actuator_gain/whole" or "actuator_gain/part".
std::string ScopeOf(const KnobCandidate& c) { return c.family + (c.WholeRobot() ? "/whole" : "/part"); }

}  // namespace

Confidence AssessConfidence(const CandidateSet& set, const Refinement& r, std::mt19937_64& rng) {
  Confidence out;
  SelectionOptions options = r.selection_options;
  out.resamples = options.bootstrap_selection;
  out.computed = options.bootstrap_selection > 0;
  if (!out.computed) options.bootstrap_selection = 0;
  const BootstrapResult boot = Bootstrap(r.problem, r.selection, options, rng);
  out.inclusion.assign(set.candidates.size(), -1.0);
  out.scope_inclusion.assign(set.candidates.size(), -1.0);
  if (out.computed) {
    for (size_t k = 0; k < boot.inclusion.size(); ++k) out.inclusion[k] = std::clamp(boot.inclusion[k], 0.0, 1.0);
    std::map<std::string, int> count, scope_count;
    for (const auto& selected : boot.selections) {
      std::set<std::string> families, scopes;
      for (int e : selected) families.insert(set.candidates[e].family), scopes.insert(ScopeOf(set.candidates[e]));
      for (const auto& f : families) ++count[f];
      for (const auto& f : scopes) ++scope_count[f];
    }
    for (size_t k = 0; k < set.candidates.size(); ++k) {
      const KnobCandidate& c = set.candidates[k];
      out.family_inclusion[c.family] = static_cast<double>(count[c.family]) / out.resamples;
      out.scope_inclusion[k] = static_cast<double>(scope_count[ScopeOf(c)]) / out.resamples;
    }
  }
  for (size_t j = 0; j < r.selection.selected.size(); ++j) {
    const int k = r.selection.selected[j];
    double lo = NAN, hi = NAN;
    if (j < boot.lower.size() && boot.lower[j].size() > 0 && options.bootstrap_parameters > 0) {
      const double a = CandidateValue(set, r, k, boot.lower[j]), b = CandidateValue(set, r, k, boot.upper[j]);
      lo = std::min(a, b), hi = std::max(a, b);
    }
    out.value_lower.push_back(lo);
    out.value_upper.push_back(hi);
  }
  return out;
}

}  // namespace dgmm::sim2real
