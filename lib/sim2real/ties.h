#pragma once
// Stage 7 of the analysis (analysis.h): for each named candidate, the candidates of other families
// (or of its own family at another scope: every servo's gain against one side's) the data cannot
// tell apart from it (TiedCandidates), the command x terrain cell where their
// fitted predictions differ most with the executions that would separate them, and the check of
// that proposal by recording the cell at each knob's fitted value (experiment_check.h).
#include <string>
#include <vector>

#include "sim2real/experiment_check.h"
#include "sim2real/refine.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real {

struct TieOptions {
  double tie_correlation = 0.9;       // |cosine| of whitened fitted shifts on the real samples
  ExperimentCheckOptions experiment;  // the check by simulation of each tie's proposed experiment
  int max_experiment_checks = 3;      // ties checked at most (the rest say so)
  bool IsValid(std::string* error) const;
};

// What a library entry stands for when ties are told apart: its family, and whether it acts on the
// whole robot (no side, no leg). Two entries can tie when their families differ, or when one acts
// on the whole robot and the other on a side or a leg of it (a side's weak servos read as every
// servo's); a side against its legs is the leg search's question (leg_search.h).
struct TieScope {
  std::string family;
  bool whole_robot = true;
  bool Distinct(const TieScope& o) const { return family != o.family || whole_robot != o.whole_robot; }
};

// Candidates of `step` (indices into fp.library, `scope` per library entry) the data cannot
// tell apart from `chosen`: of a distinct scope (TieScope::Distinct), and either flagged by the selection (gain within
// one SE of the paired difference, correlated fitted shifts) or with a held-out gain within two
// SE of the best and whitened fitted shifts (each effect fitted alone on all samples) at
// |cosine| >= tie_correlation. `correlation` (optional) gets the |cosine| of each.
std::vector<int> TiedCandidates(const FitProblem& fp, const SelectionStep& step, int chosen,
                                const std::vector<TieScope>& scope, double tie_correlation,
                                const EffectFitOptions& fit, std::vector<double>* correlation = nullptr);

struct CandidateTie {
  int candidate = -1;  // the named candidate the tie belongs to
  VerdictTie tie;      // families[0] is its own
};

struct TieResult {
  std::vector<CandidateTie> ties;
  int experiment_checks = 0;
  double experiment_seconds = 0;
};

// Ties of each candidate in `named` (in that order); `spread_scale` scales the simulated
// within-cell spread (the fitted noise scale, >= 1). `simulator` may be null (no checks).
TieResult FindTies(const KnobSimulator* simulator, const AnalysisInputs& in, const Baseline& base,
                   const CandidateSet& set, const Refinement& r, const std::vector<int>& named,
                   const TieOptions& options);

}  // namespace dgmm::sim2real
