#pragma once
// The EM reference as a motion model: one full-covariance mixture per command over y = x || z
// (x alone without terrain), each fitted by FitEm (em.h). Used by `dgmm em` and the Python module.
#include <functional>
#include <map>
#include <string>

#include "core/motion_model.h"
#include "core/sample_set.h"
#include "em/em.h"

namespace dgmm {

struct EmModelResult {
  MotionModel model;                      // kind "em"
  std::map<int, EmSummary> summaries;     // per command id
};

// Fits every command of `set` that has samples, in command order; `progress(done, total)` after
// each command (samples). Throws InputError naming `source` and the command when it has fewer
// samples than components or when every restart of its EM failed.
EmModelResult FitEmMotionModel(const SampleSet& set, const EmOptions& options, bool with_terrain,
                               const std::string& source,
                               const std::function<void(long long, long long)>& progress = {});

}  // namespace dgmm
