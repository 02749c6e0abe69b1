#include "sim2real/confidence.h"

#include <algorithm>
#include <set>

namespace dgmm::sim2real {

Confidence AssessConfidence(const CandidateSet& set, const Refinement& r, std::mt19937_64& rng) {
  Confidence out;
  SelectionOptions options = r.selection_options;
  out.resamples = options.bootstrap_selection;
  out.computed = options.bootstrap_selection > 0;
  if (!out.computed) options.bootstrap_selection = 0;
  const BootstrapResult boot = Bootstrap(r.problem, r.selection, options, rng);
  out.inclusion.assign(set.candidates.size(), -1.0);
  if (out.computed) {
    for (size_t k = 0; k < boot.inclusion.size(); ++k) out.inclusion[k] = std::clamp(boot.inclusion[k], 0.0, 1.0);
    std::map<std::string, int> count;
    for (const auto& selected : boot.selections) {
      std::set<std::string> families;
      for (int e : selected) families.insert(set.candidates[e].family);
      for (const auto& f : families) ++count[f];
    }
    for (const auto& c : set.candidates) {
      out.family_inclusion[c.family] = static_cast<double>(count[c.family]) / out.resamples;
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
