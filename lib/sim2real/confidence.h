#pragma once
// Stage 5 of the analysis (analysis.h): how stable the selection is. The whole selection is
// repeated on bootstrap resamples of the real episodes; a candidate's inclusion is the share of
// resamples selecting it, a family's the share selecting any candidate of that family (two probes
// of one knob are one physics). Each selected candidate's coefficients get a 95% percentile
// interval from refits on resamples, and its value in the knob's unit the interval's image.
// Inclusion measures stability within the candidate list, not that the list holds the truth
// (that is the adequacy stage's question).
#include <map>
#include <random>
#include <string>
#include <vector>

#include "sim2real/refine.h"

namespace dgmm::sim2real {

struct Confidence {
  bool computed = false;                       // bootstrap_selection > 0
  int resamples = 0;
  std::vector<double> inclusion;               // per candidate, in [0, 1]
  std::map<std::string, double> family_inclusion;
  // Per candidate: the share of resamples selecting any candidate of its family at its scope, the
  // whole robot (no side, no leg) or a part of it (a side or a leg): every servo's gain and one
  // side's are one family but two claims.
  std::vector<double> scope_inclusion;
  // Per entry of the final selection (its order): the value's 95% interval in the knob's unit.
  std::vector<double> value_lower, value_upper;
};

Confidence AssessConfidence(const CandidateSet& set, const Refinement& r, std::mt19937_64& rng);

}  // namespace dgmm::sim2real
