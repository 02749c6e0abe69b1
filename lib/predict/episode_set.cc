#include "predict/episode_set.h"

#include "util/error.h"

namespace dgmm::predict {

void CheckEpisodeSet(const MotionModel& model, const SampleSet& set, const std::string& source, const std::string& use) {
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(source, "", e);
  if (!set.has_sequence()) {
    throw MakeInputError(source, "episode", use + " needs recorded episodes and steps (e.g. dgmm simulate --protocol trajectories)");
  }
  if (!set.transform.empty()) throw MakeInputError(source, "transform", "expected a raw (not standardised) set");
  if (set.pose_dim() != model.pose_dim) throw MakeInputError(source, "x", "expected the model's pose dimensions");
  if (model.terrain_dim > 0 && set.terrain_dim() != model.terrain_dim) {
    throw MakeInputError(source, "z", "expected the model's " + std::to_string(model.terrain_dim) + " terrain dimensions");
  }
}

}  // namespace dgmm::predict
