#include "sim2real/runoff.h"

#include <algorithm>
#include <cmath>

#include "sim2real/sentence_format.h"
#include "sim2real/verdict_stage.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

bool OneParameter(const Knob& k) { return k.role == Knob::Role::kShift || k.role == Knob::Role::kPayloadMass; }

// nominal + t (probe - nominal) for every t, inside the knob's range and physical limit, distinct.
std::vector<double> StepValues(const Knob& k, double probe, const std::vector<double>& steps) {
  std::vector<double> out;
  for (double t : steps) {
    const double v = WithinKnob(k, k.nominal + t * (probe - k.nominal));
    const double tol = 1e-9 * std::max(std::fabs(k.nominal), std::fabs(probe));
    if (v != k.nominal && std::none_of(out.begin(), out.end(), [&](double u) { return std::fabs(u - v) <= tol; })) {
      out.push_back(v);
    }
  }
  return out;
}

// The knob's probe on the side of the nominal where the contender's mean shift alone reads it:
// its fit on every real sample, v = nominal + a (at - nominal), `at` the value its signature was
// last recorded at (the probe, or the refinement's value); with no probe on that side, the first
// probe mirrored about the nominal.
double ProbeOnTheReadingsSide(const CandidateSet& set, const Refinement& r, int effect, const Knob& knob) {
  const KnobCandidate& kc = set.candidates[effect];
  const double probe = kc.key == "payload" ? knob.probes.front() : kc.probe;
  const double at = effect < static_cast<int>(r.signature_at.size()) && std::isfinite(r.signature_at[effect])
                        ? r.signature_at[effect] : probe;
  const double side = FitEffects(r.problem, {effect}, {}, r.selection_options.fit).theta[0](0) * (at - knob.nominal);
  if (side == 0) return probe;
  for (double p : knob.probes) {
    if ((p - knob.nominal) * side > 0) return p;
  }
  return 2 * knob.nominal - knob.probes.front();
}

}  // namespace

bool RunoffOptions::IsValid(std::string* error) const {
  if (max_contenders < 1 || steps.empty() ||
      std::any_of(steps.begin(), steps.end(), [](double t) { return !(t > 0) || !std::isfinite(t); })) {
    *error = "runoff: max_contenders >= 1 and positive steps expected";
    return false;
  }
  return search.IsValid(error);
}

std::vector<std::pair<int, double>> RunoffGrid(const KnobSimulator& simulator, const CandidateSet& set,
                                               const Refinement& r, const RunoffOptions& options,
                                               std::vector<std::string>* contenders) {
  std::vector<std::pair<int, double>> grid;
  std::vector<int> knobs_in;
  if (r.selection.steps.empty()) return grid;
  const SelectionStep& first = r.selection.steps.front();
  for (const CandidateScore& c : first.candidates) {  // by gain, the chosen one first
    if (!(c.z > first.threshold_z && c.gain > r.selection_options.min_gain_nats)) continue;
    const KnobCandidate& kc = set.candidates[c.effect];
    const int k = kc.key == "payload" ? set.payload_knob[0] : kc.knob_index;
    if (!kc.simulated || k < 0 || !OneParameter(simulator.knobs()[k])) continue;
    if (std::find(knobs_in.begin(), knobs_in.end(), k) != knobs_in.end()) continue;
    if (static_cast<int>(knobs_in.size()) >= options.max_contenders) break;
    const Knob& knob = simulator.knobs()[k];
    const double probe = ProbeOnTheReadingsSide(set, r, c.effect, knob);
    knobs_in.push_back(k);
    contenders->push_back(knob.name + Fmt("@%.3g", probe));
    for (double v : StepValues(knob, probe, options.steps)) grid.push_back({k, v});
  }
  return grid;
}

Runoff RunRunoff(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                 const Refinement& r, const CandidateOptions& recording, const RunoffOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "runoff options", error);
  Runoff out;
  const auto grid = RunoffGrid(simulator, set, r, options, &out.contenders);
  if (out.contenders.empty()) {
    out.why_not = "no simulator knob was significant at the first selection step";
    return out;
  }
  out.ran = true;
  out.search = SearchOwnModels(simulator, in, set, recording, options.search, grid);
  out.search.by = "runoff";
  return out;
}

void AddRunoff(const KnobSimulator& simulator, Runoff* runoff, Verdict* v) {
  if (!runoff->ran) return;
  runoff->named_before = v->named.empty() ? "" : v->named.front().knob;
  const LegSearch& s = runoff->search;
  const std::string list = Fmt("%.0f recordings of ", static_cast<double>(s.points.size())) +
                           JoinWords(runoff->contenders) + ", each scored by a model of its own";
  if (!s.named) {
    const std::string doubt = "on this uneven ground a runoff (" + list + ") names no knob: " + s.why;
    if (!v->named.empty()) {
      v->named.front().doubts.push_back(doubt);
      AddVerdictDoubt(doubt, v);
    }
    v->sentence += " On this uneven ground a runoff (" + list + ") names no knob: " + s.why + ".";
    return;
  }
  const Knob& k = simulator.knobs()[s.knob_index];
  VerdictNamed n = SearchNamed(s, k.family, k.unit);
  const std::string& before = runoff->named_before;
  n.doubts.push_back("found by a runoff on uneven ground (" + list +
                     ") after the probes' mean shifts: no bootstrap, its range is the values that fit as well" +
                     (before.empty() || before == k.name ? "" : "; the mean shifts had named " + before));
  AddRemainingMismatchDoubt(s, "it", &n);
  v->ties.clear();
  ReplaceNamed(s, n, v);
  v->sentence += " " + k.name + Fmt(" at %.3g fits the real samples %.3g nats per sample better than the nominal ",
                                    s.value, s.points[s.best].score - s.nominal_score) +
                 Fmt("(z %.1f); no other contender fits as well.", s.z_vs_nominal);
}

}  // namespace dgmm::sim2real
