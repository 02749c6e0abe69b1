#pragma once
// How a sample set is split into cross-validation folds, chosen from what the data supports, with
// the reason in one line for every report (`dgmm cv`, `dgmm tune`).
#include <string>

#include "core/sample_set.h"

namespace dgmm {

struct FoldPlan {
  int folds = 0;
  bool by_episode = false;  // whole episodes per fold (else stratified by command)
  int episodes = 0;         // distinct episode ids in the set (0: no episode data)
  std::string reason;       // one line, e.g. "leave-one-episode-out (6 episodes, fewer than 10)"
};

// The folds for `set`. requested > 0: that many (by episode when group_by_episode and the set has
// at least `requested` episodes, else stratified by command, and the reason says why).
// requested == 0 (automatic): with >= 2 episodes and group_by_episode, min(max_auto_folds, E)
// folds of whole episodes, i.e. leave-one-episode-out when E <= max_auto_folds; otherwise
// stratified with min(max_auto_folds, m) folds, m the smallest sample count of a command with at
// least two samples (so every such command is in every fold), at least 2. Throws InputError
// naming --folds and the fix when no split can score anything (fewer than 2 samples, or every
// command has a single sample). max_auto_folds >= 2 (asserted).
FoldPlan ChooseFolds(const SampleSet& set, int requested, bool group_by_episode,
                     int max_auto_folds = 10);

}  // namespace dgmm
