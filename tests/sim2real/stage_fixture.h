#pragma once
// The stages of the analysis run one by one on a fake pair, for the tests of each stage.
#include <random>

#include "sim2real/analysis.h"
#include "tests/sim2real/fake_simulator.h"

namespace dgmm::sim2real::test {

inline const FakeSimulator& SharedFake() {
  static const FakeSimulator fake;
  return fake;
}

struct Stages {
  AnalysisOptions options = FastOptions();
  AnalysisInputs in;
  Baseline base;
  CandidateSet set;
  Refinement refinement;
  Confidence confidence;
  NullShortfall null;
  Adequacy adequacy;
  Naming naming;
};

// Runs the stages up to and including `last` (2 baseline, 3 candidates, 4 refine, 5 confidence,
// 6 adequacy and naming).
inline Stages RunStages(const FakeSimulator& fake, const std::vector<KnobValue>& planted, int last,
                        const FakeExtras& extras = {}, const AnalysisOptions& options = FastOptions()) {
  Stages s;
  s.options = options;
  const FakePair pair = MakeFakePair(fake, planted, extras);
  s.in = PrepareInputs(pair.sim, pair.real, s.options.seed);
  s.base = LocateMismatch(s.in, s.options.locate);
  if (last < 3) return s;
  s.set = BuildCandidates(fake, s.in, s.base, s.options.candidates);
  if (last < 4) return s;
  s.refinement = SelectAndRefine(fake, s.in, s.base, s.options.candidates, s.options.refine, &s.set);
  if (last < 5) return s;
  std::mt19937_64 rng(2);
  s.confidence = AssessConfidence(s.set, s.refinement, rng);
  if (last < 6) return s;
  s.null = MeasureNullShortfall(s.in, s.base, s.options.locate.model, s.options.adequacy);
  s.adequacy = AssessAdequacy(s.in, s.base, s.null, s.set, s.refinement, s.options.adequacy);
  s.naming = DecideNamed(s.set, s.refinement, s.confidence, s.adequacy, s.options.verdict);
  return s;
}

inline Stages RunStages(const std::vector<KnobValue>& planted, int last, const FakeExtras& extras = {}) {
  return RunStages(SharedFake(), planted, last, extras);
}

// An `unexplained` verdict that named nothing and located 12 regions: what a search that names a
// knob replaces (its status, sentence and doubts).
inline Verdict UnexplainedInRegions() {
  Verdict v;
  v.status = "unexplained";
  v.doubts = {"mismatch left in 12 regions"};
  v.sentence = "Unexplained mismatch: no simulator knob or measurement effect fits.";
  return v;
}

inline int CandidateOf(const CandidateSet& set, const std::string& key) {
  for (size_t k = 0; k < set.candidates.size(); ++k) {
    if (set.candidates[k].key == key) return static_cast<int>(k);
  }
  return -1;
}

}  // namespace dgmm::sim2real::test
