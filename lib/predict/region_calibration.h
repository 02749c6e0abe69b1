#pragma once
// Calibrated prediction regions (split conformal prediction): the planar regions of a prediction
// hold their shares of the model's own trajectories, which is the share of outcomes only when the
// model's spread is the robot's. Held-out episodes, recorded like the sequences to predict and not
// learnt from, measure the difference: each episode's command sequence is predicted from its start
// on its recorded terrain, and after k commands the ratio
//   q_k = d2(outcome) / r2_level,k
// of the outcome's squared Mahalanobis distance to the level's region radius is taken; the factor
// on r2 at horizon k is the ceil((n + 1) level)-th smallest of the n ratios, so that a new
// episode's outcome falls inside the widened (or narrowed) region with probability >= level when
// it is exchangeable with the held-out ones.
#include <string>
#include <vector>

#include "core/motion_model.h"
#include "core/sample_set.h"
#include "predict/predict.h"

namespace dgmm::predict {

struct CalibrationOptions {
  int min_episodes = 20;  // a horizon reached by fewer episodes takes the previous horizon's factor
};

// `prediction`: the options the calibrated predictions will use (persistence, pose dimensions,
// trajectories, seed, region_levels: the levels calibrated; its own calibration is ignored). The set must be raw, record episodes and steps, and give
// the model's pose and terrain dimensions; each episode starts at its step 0 and runs to its
// first missing step. InputError naming `source` and the part otherwise, or when no horizon is
// reached by options.min_episodes episodes.
RegionCalibration CalibrateRegions(const MotionModel& model, const SampleSet& held_out,
                                   const PredictOptions& prediction, const CalibrationOptions& options = {},
                                   const std::string& source = "sample set");

}  // namespace dgmm::predict
