#include "tune/fold_plan.h"

#include <gtest/gtest.h>

#include "tests/tune/synthetic.h"
#include "tune/cross_validation.h"
#include "util/error.h"

namespace dgmm {
namespace {

// `episodes` episodes of equal length over the set, in recording order.
SampleSet WithEpisodes(SampleSet set, int episodes) {
  set.episode.resize(set.size());
  set.step.resize(set.size());
  for (int i = 0; i < set.size(); ++i) {
    set.episode(i) = i * episodes / set.size();
    set.step(i) = i;
  }
  return set;
}

TEST(ChooseFolds, LeaveOneEpisodeOutWhenEpisodesAreFew) {
  const SampleSet set = WithEpisodes(test::MakeTerrainSet(3, 10, 1.0, 1), 6);
  const FoldPlan plan = ChooseFolds(set, 0, true);
  EXPECT_TRUE(plan.by_episode);
  EXPECT_EQ(plan.folds, 6);
  EXPECT_EQ(plan.episodes, 6);
  EXPECT_NE(plan.reason.find("leave-one-episode-out (6 episodes"), std::string::npos)
      << plan.reason;
}

TEST(ChooseFolds, TenFoldsOfWholeEpisodesWhenThereAreMany) {
  // 41 trials of 15 commands: some command has only two or three samples, which refused the
  // default 10 folds before (issue #24) although every fold holds whole episodes.
  SampleSet set = test::MakeTerrainSet(15, 3, 1.0, 2);
  set = WithEpisodes(set.Subset([] {
    std::vector<int> rows;
    for (int i = 0; i < 41; ++i) rows.push_back(i);
    return rows;
  }()),
                     41);
  const FoldPlan plan = ChooseFolds(set, 0, true);
  EXPECT_TRUE(plan.by_episode);
  EXPECT_EQ(plan.folds, 10);
  EXPECT_NE(plan.reason.find("10 folds of whole episodes (41 episodes, at most 10 folds)"),
            std::string::npos)
      << plan.reason;
  CvOptions options;
  options.folds = 0;
  options.repeats = 1;
  options.em_baseline = false;
  options.dgmm.k = 0.5;
  const CvSummary cv = CrossValidate(set, options);
  EXPECT_EQ(cv.folds, 10);
  EXPECT_EQ(cv.folds_by, plan.reason);
}

TEST(ChooseFolds, StratifiedBySmallestCommandWithoutEpisodes) {
  SampleSet set = test::MakeTerrainSet(3, 4, 1.0, 3);  // 4 samples per command, no episodes
  FoldPlan plan = ChooseFolds(set, 0, true);
  EXPECT_FALSE(plan.by_episode);
  EXPECT_EQ(plan.folds, 4);
  EXPECT_NE(plan.reason.find("no episode data"), std::string::npos) << plan.reason;
  // Explicit folds are kept; with too few episodes they are stratified and the reason says why.
  set = WithEpisodes(set, 3);
  plan = ChooseFolds(set, 5, true);
  EXPECT_FALSE(plan.by_episode);
  EXPECT_EQ(plan.folds, 5);
  EXPECT_NE(plan.reason.find("only 3 episodes for 5 folds"), std::string::npos) << plan.reason;
  plan = ChooseFolds(set, 0, false);
  EXPECT_FALSE(plan.by_episode);
  EXPECT_NE(plan.reason.find("asked"), std::string::npos) << plan.reason;
  const SampleSet big = test::MakeTerrainSet(2, 40, 1.0, 4);
  EXPECT_EQ(ChooseFolds(big, 0, true).folds, 10);
}

TEST(ChooseFolds, NoValidSplitIsAnErrorNamingTheFix) {
  SampleSet set = test::MakeTerrainSet(3, 1, 1.0, 5);  // one sample per command
  try {
    ChooseFolds(set, 0, true);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--folds"), std::string::npos) << what;
    EXPECT_NE(what.find("record more samples"), std::string::npos) << what;
  }
  // Two episodes are a valid split even then: leave-one-episode-out.
  EXPECT_EQ(ChooseFolds(WithEpisodes(set, 2), 0, true).folds, 2);
}

}  // namespace
}  // namespace dgmm
