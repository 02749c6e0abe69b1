#include "tune/fold_plan.h"

#include <algorithm>
#include <cassert>
#include <map>
#include <set>

#include "util/error.h"

namespace dgmm {

FoldPlan ChooseFolds(const SampleSet& set, int requested, bool group_by_episode,
                     int max_auto_folds) {
  assert(max_auto_folds >= 2);
  FoldPlan plan;
  if (set.has_sequence()) {
    plan.episodes =
        static_cast<int>(std::set<int>(set.episode.data(), set.episode.data() + set.size()).size());
  }
  const int e = plan.episodes;
  std::map<int, int> per_command;
  for (int i = 0; i < set.size(); ++i) ++per_command[set.command(i)];
  int smallest = 0;  // of the commands with >= 2 samples
  for (const auto& [c, n] : per_command) {
    if (n >= 2 && (smallest == 0 || n < smallest)) smallest = n;
  }
  const std::string automatic = requested == 0 ? "automatic: " : "";
  // Whole episodes per fold when asked for and the set has enough of them.
  if (group_by_episode && e >= 2 && (requested == 0 || requested <= e)) {
    plan.by_episode = true;
    plan.folds = requested > 0 ? requested : std::min(max_auto_folds, e);
    if (plan.folds == e) {
      plan.reason =
          automatic + "leave-one-episode-out (" + std::to_string(e) + " episodes" +
          (requested == 0 ? ", at most " + std::to_string(max_auto_folds) + " folds" : "") + ")";
    } else {
      plan.reason =
          automatic + std::to_string(plan.folds) + " folds of whole episodes (" +
          std::to_string(e) + " episodes" +
          (requested == 0 ? ", at most " + std::to_string(max_auto_folds) + " folds" : "") + ")";
    }
    return plan;
  }
  if (set.size() < 2 || smallest == 0) {
    throw MakeInputError("", "--folds",
                         "no valid cross-validation split: " + std::to_string(set.size()) +
                             " samples and no command with two of them (a held-out sample needs "
                             "a training sample of its command); record more samples per command");
  }
  std::string why;
  if (!group_by_episode) {
    why = "asked";
  } else if (!set.has_sequence()) {
    why = "the set has no episode data";
  } else if (e < 2) {
    why = "only one episode";
  } else {
    why = "only " + std::to_string(e) + " episodes for " + std::to_string(requested) + " folds";
  }
  plan.folds = requested > 0 ? requested : std::clamp(smallest, 2, max_auto_folds);
  plan.reason =
      automatic + std::to_string(plan.folds) + " folds stratified by command (" + why +
      (requested == 0 ? "; smallest command with 2+ samples has " + std::to_string(smallest) : "") +
      ")";
  return plan;
}

}  // namespace dgmm
