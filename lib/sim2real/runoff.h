#pragma once
// Stage 8a of the analysis (analysis.h): on uneven ground, a runoff of the first selection step's
// contenders, each scored by a model of its own. Where the robot stands among stones decides
// whether it walks on or hangs up, so a knob changes how often each happens more than where the
// robot goes on average, and the probes' mean shifts (signatures.h) tell a slipping foot from a
// limp joint poorly (docs/sim2real.md, "Rough ground"). Here the simulator knobs whose mean shift
// was significant at the first step are recorded at `steps` of their probe's distance from the
// nominal (the probe on the side where the knob's mean shift alone reads it), and the leg search's own-model score (leg_search.h, SearchOwnModels) decides:
//   l(k, v) = sum_i log p_{k,v}(x_i | c_i, z_i, f_i),
// the best knob named when it beats the nominal re-recording by z SE, no other knob fits as well
// and it removes enough of the nominal's misfit; otherwise the verdict says what the runoff could
// not tell apart.
#include <string>
#include <vector>

#include "sim2real/leg_search.h"
#include "sim2real/refine.h"

namespace dgmm::sim2real {

struct RunoffOptions {
  bool enabled = true;
  bool only_on_uneven_ground = true;  // locate permuted whole placements (Baseline::permute_placements)
  int max_contenders = 3;             // simulator knobs, by their first-step gain
  std::vector<double> steps = {0.5, 1.0, 1.5};  // t in v = nominal + t (probe - nominal), clipped to the range
  LegSearchOptions search;            // the scoring and naming rules (its factors unused)
  RunoffOptions() { search.refine_steps = 2; }
  bool IsValid(std::string* error) const;
};

struct Runoff {
  bool ran = false;
  std::string why_not;                  // why it did not run
  std::vector<std::string> contenders;  // "knob@probe", in order of their first-step gain
  std::string named_before;             // the knob the mean shifts named first ("" for none; AddRunoff)
  LegSearch search;
};

// The (knob, value) points of the contenders: simulated one-parameter candidates (shift or payload
// mass) significant at the first step of the final selection, at most max_contenders knobs, each
// towards its probe on the side of the nominal where its mean shift alone reads it.
std::vector<std::pair<int, double>> RunoffGrid(const KnobSimulator& simulator, const CandidateSet& set,
                                               const Refinement& r, const RunoffOptions& options,
                                               std::vector<std::string>* contenders);

Runoff RunRunoff(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                 const Refinement& r, const CandidateOptions& recording, const RunoffOptions& options);

// The runoff's answer in the verdict: a named knob replaces the verdict's (status partly_explained,
// with the doubts of a search without bootstrap); otherwise a named knob keeps its place with the
// runoff's doubt, and the sentence says what the runoff could not tell apart.
// Records in `runoff` what the verdict named before (Runoff::named_before).
void AddRunoff(const KnobSimulator& simulator, Runoff* runoff, Verdict* verdict);

}  // namespace dgmm::sim2real
