#pragma once
// Stage 8 of the analysis (analysis.h): the verdict (verdict.h) from what the stages before
// decided. First which selected candidates are named (DecideNamed, before the ties stage, which
// only looks at those), then the status, the doubts and the sentence (ComposeVerdict).
#include <string>
#include <vector>

#include "sim2real/adequacy.h"
#include "sim2real/ties.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real {

struct VerdictOptions {
  double min_inclusion = 0.5;        // family inclusion below which a selected candidate is not named
  // A named family's inclusion below which its name is a doubt (the resamples often read the data
  // otherwise): the sprawled quadruped's 55031, a rear tibia shortened to 68% named as a tracker
  // offset at 65% and `explained`; 54202, a weak front leg as soft servos at 75%.
  double sure_inclusion = 0.8;
  double noise_structure_p = 0.01;   // residual means by command or terrain below this withhold tracker noise
  bool IsValid(std::string* error) const;
};

struct Naming {
  std::vector<int> named;            // candidates, by importance
  std::vector<int> drifting;         // selected, not constant (drift.h): positions in adequacy.drift_tests
  std::vector<int> weak;             // selected, family inclusion under the threshold
  bool structured = false;           // residual structure within placements or in the tails
  bool noise_withheld = false;       // tracker noise fits but what remains is not a pure change of scale
  bool spread_from_knobs = false;    // a wider real spread the named knobs already make in simulation
};

Naming DecideNamed(const CandidateSet& set, const Refinement& r, const Confidence& confidence, const Adequacy& adequacy,
                   const VerdictOptions& options);

Verdict ComposeVerdict(const Baseline& base, const CandidateSet& set, const Refinement& r, const Confidence& confidence,
                       const Adequacy& adequacy, const Naming& naming, const TieResult& ties,
                       const VerdictOptions& options);

// The verdict without a simulator: "clean" when nothing is located, else "located" with where.
Verdict LocateOnlyVerdict(const Baseline& base, const std::string& why);

// The plain-language paragraph of a verdict (verdict_sentence.cc).
std::string VerdictSentence(const Verdict& v, const Adequacy* adequacy, const Naming* naming, const Refinement* r);

}  // namespace dgmm::sim2real
