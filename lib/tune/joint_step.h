#pragma once
// Internal to lib/tune. The joint step of `dgmm tune` (lib/tune/tune_k.h, step 3): a design around
// the coordinate steps' choice in v = (log k, log f, log nu0), a concave quadratic surrogate fitted
// and maximised in the design's box with Ceres (tune/quadratic_surrogate.h), L cross-validated at
// its maximiser, then the acceptance and plateau rules.
#include <vector>

#include "tune/tune_evaluator.h"
#include "tune/tune_k.h"

namespace dgmm {

// The typical step of a geometric grid in log units: the median log ratio of neighbours (log 3
// for a grid of fewer than two distinct values).
double LogGridStep(std::vector<double> grid);

// Runs options.joint_rounds rounds from *chosen (f tuned when tune_scale, nu0 when tune_prior);
// updates *chosen, evaluate's f and nu0, and summary->joint.
void JointStep(const TuneKOptions& options, bool tune_scale, bool tune_prior,
               TuneEvaluator& evaluate, TuneKPoint* chosen, TuneKSummary* summary);

}  // namespace dgmm
