#pragma once
// A sample set of recorded episodes (episode and step per sample, e.g. dgmm simulate --protocol
// trajectories) read against a model: what the persistence estimate and the region calibration
// learn from.
#include <string>

#include "core/motion_model.h"
#include "core/sample_set.h"

namespace dgmm::predict {

// The set is valid, records episodes and steps, is raw (not standardised) and has the model's
// pose and terrain dimensions; InputError naming `source` and the part otherwise, saying that
// `use` ("persistence", "calibration") needs them.
void CheckEpisodeSet(const MotionModel& model, const SampleSet& set, const std::string& source, const std::string& use);

}  // namespace dgmm::predict
