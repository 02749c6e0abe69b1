#include "sim2real/more_data.h"

#include <algorithm>
#include <cmath>

#include "sim2real/selection.h"
#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// The step that chose library effect k (nullptr: none).
const SelectionStep* ChoosingStep(const SelectionResult& s, int k) {
  for (const SelectionStep& step : s.steps) {
    if (step.chosen == k) return &step;
  }
  return nullptr;
}

// The first weak knob's evidence: its z where it was chosen, z_eff from its family's inclusion.
bool FromWeak(const CandidateSet& set, const Refinement& r, const Naming& naming, const Verdict& v,
              int resamples, MoreData* m) {
  if (naming.weak.empty() || v.weak.empty()) return false;
  const int k = naming.weak.front();
  const SelectionStep* step = ChoosingStep(r.selection, k);
  if (!step) return false;
  const auto own = std::find_if(step->candidates.begin(), step->candidates.end(),
                                [k](const CandidateScore& c) { return c.effect == k; });
  if (own == step->candidates.end()) return false;
  const double floor = 0.5 / std::max(resamples, 1);  // the share one resample in 2B would give
  m->reason = "inclusion";
  m->knob = set.candidates[k].knob, m->family = set.candidates[k].family;
  m->z = own->z, m->z_required = step->threshold_z;
  m->inclusion = v.weak.front().inclusion;
  m->z_effective = m->z_required - UpperQuantile(std::clamp(m->inclusion, floor, 1 - floor));
  return true;
}

// The first step's best candidate when it came near significance.
bool FromNearMiss(const CandidateSet& set, const Refinement& r, const MoreDataOptions& options, MoreData* m) {
  const CandidateScore* best = FirstStepBest(r.selection);
  if (!best || r.selection.steps[0].chosen >= 0) return false;
  const SelectionStep& first = r.selection.steps[0];
  if (!(best->z >= options.from_z && best->z < first.threshold_z)) return false;
  m->reason = "near_miss";
  m->knob = set.candidates.at(best->effect).knob, m->family = set.candidates.at(best->effect).family;
  m->z = m->z_effective = best->z, m->z_required = first.threshold_z;
  return true;
}

// The searches' near miss nearest its bar (by z / bar), and the factor of placements it needs
// (more_data.h; infinite where the walk's own chance bounds its z below the aim).
bool FromSearch(const std::vector<SearchNearMiss>& near, const MoreDataOptions& options, MoreData* m, double* factor) {
  const SearchNearMiss* best = nullptr;
  for (const SearchNearMiss& s : near) {
    if (!(s.z >= options.search_from_z && s.z < s.bar && s.gain > 0 && s.samples > 1)) continue;
    if (!best || s.z / s.bar > best->z / best->bar) best = &s;
  }
  if (!best) return false;
  m->reason = "search_near_miss";
  m->knob = best->knob, m->family = best->family;
  m->said = best->by + "'s best point (" + best->said + ")";
  m->z = m->z_effective = best->z, m->z_required = best->bar;
  m->chance = best->chance;
  const double n = best->samples, aim = best->bar + options.margin;
  const double se2 = std::pow(n * best->gain / best->z, 2) - std::pow(n * best->chance, 2);
  const double room = std::pow(best->gain / aim, 2) - std::pow(best->chance, 2);
  *factor = se2 > 0 && room > 0 ? se2 / (n * n * room) : INFINITY;
  return true;
}

}  // namespace

bool MoreDataOptions::IsValid(std::string* error) const {
  if (!(from_z > 0) || !(margin >= 0) || !(max_factor > 1) || !(search_from_z > 0)) {
    *error = "more data: from_z > 0, search_from_z > 0, margin >= 0 and max_factor > 1 expected";
    return false;
  }
  return true;
}

MoreData AdviseMoreData(const AnalysisInputs& in, const CandidateSet& set, const Refinement& r, const Naming& naming,
                        const Verdict& v, const std::vector<std::string>& searched, const MoreDataOptions& options,
                        const std::vector<SearchNearMiss>& near) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "analysis options", error);
  MoreData m;
  if (!options.enabled || !v.named.empty() || v.status != "unexplained") return m;
  if (v.uneven_ground && !options.on_uneven_ground) return m;
  bool selected = FromWeak(set, r, naming, v, r.selection_options.bootstrap_selection, &m) || FromNearMiss(set, r, options, &m);
  if (selected && std::find(searched.begin(), searched.end(), m.knob) != searched.end()) m = MoreData{}, selected = false;
  double factor = INFINITY;
  if (selected) {
    factor = m.z_effective > 0 ? std::pow((m.z_required + options.margin) / m.z_effective, 2) : INFINITY;
  } else if (!FromSearch(near, options, &m, &factor)) {
    return MoreData{};
  }
  const PlacementCount count = RealPlacements(in);
  m.sequence = in.real_set.has_sequence();
  m.placements = count.placements, m.executions_per_placement = count.executions_per_placement;
  m.placements_needed = factor > options.max_factor ? -1 : static_cast<int>(std::ceil(m.placements * factor));
  m.max_factor = options.max_factor;
  m.advised = true;
  return m;
}

namespace {

// The search's near miss (MoreData::reason "search_near_miss") in words.
std::string SearchNearMissSentence(const MoreData& m, const std::string& unit) {
  std::string s = " The evidence stops short of a name: " + m.said +
                  Fmt(" fits the real samples better than the nominal by z %.2f", m.z) +
                  Fmt(" (named from %.2f). The real set has %.0f ", m.z_required, m.placements) + unit;
  if (m.sequence) s += Fmt(" of %.0f executions", m.executions_per_placement);
  if (m.placements_needed < 0) {
    return s + (m.chance > 0 ? Fmt("; the walk's own chance in the search's score (%.3g nats per real sample) bounds that "
                                   "z, so more ", m.chance) + unit + " alone are unlikely to decide it."
                             : Fmt("; the gain is too small for this protocol: more than %.0f times as many ", m.max_factor) +
                                   unit + " would be needed to decide it.");
  }
  return s + "; its z grows about with the square root of the " + unit +
         Fmt(", so at least about %.0f ", m.placements_needed) + unit +
         " would be needed to decide it (the best of the search's points tends to overstate its gain).";
}

}  // namespace

std::string MoreDataSentence(const MoreData& m) {
  if (!m.advised) return "";
  const std::string unit = m.sequence ? "placements" : "samples";
  if (m.reason == "search_near_miss") return SearchNearMissSentence(m, unit);
  std::string s = " The evidence stops short of a name: " + m.family + " (" + m.knob + ")";
  s += m.reason == "inclusion"
           ? Fmt(" was selected (held-out z %.2f", m.z) + Fmt(", significant from %.2f) but held in %.0f%% of the resamples",
                                                             m.z_required, 100 * m.inclusion)
           : Fmt(" reached held-out z %.2f at the first selection step (significant from %.2f)", m.z, m.z_required);
  s += Fmt(". The real set has %.0f ", m.placements) + unit;
  if (m.sequence) s += Fmt(" of %.0f executions", m.executions_per_placement);
  if (m.placements_needed < 0 && m.reason == "inclusion") {  // selected, yet the resamples rarely agree
    return s + Fmt("; more placements alone are unlikely to settle it: at the rate the resamples agree, more than %.0f "
                   "times as many ", m.max_factor) + unit + " would be needed.";
  }
  if (m.placements_needed < 0) {
    return s + Fmt("; the effect is too small for this protocol: more than %.0f times as many ", m.max_factor) + unit +
           " would be needed to name it.";
  }
  const double z_then = m.z_effective * std::sqrt(static_cast<double>(m.placements_needed) / m.placements);
  s += "; a held-out z grows with the square root of the " + unit;
  if (m.reason == "near_miss") {  // the best of the first step, picked for being high: it overstates its effect
    return s + Fmt(", so at least about %.0f ", m.placements_needed) + unit +
           Fmt(" would be needed to decide it (z %.1f at the near miss's size, which the best of several candidates "
               "tends to overstate).", z_then);
  }
  return s + Fmt(", so about %.0f ", m.placements_needed) + unit +
         Fmt(" would decide it (z %.1f expected at the effect's present size).", z_then);
}

}  // namespace dgmm::sim2real
