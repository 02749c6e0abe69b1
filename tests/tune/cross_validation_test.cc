#include "tune/cross_validation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "tests/tune/synthetic.h"
#include "util/error.h"

namespace dgmm {
namespace {

CvOptions SmallOptions() {
  CvOptions options;
  options.folds = 5;
  options.repeats = 3;
  options.seed = 7;
  options.dgmm.k = 0.5;
  options.em_max_components = 2;
  options.em.n_init = 1;
  return options;
}

TEST(EpisodeFolds, NeverSplitAnEpisodeAndBalanceSizes) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    std::mt19937_64 make(seed);
    const int folds = 2 + static_cast<int>(make() % 9);
    const int episodes = folds + static_cast<int>(make() % 30);
    std::vector<int> ids;
    for (int e = 0; e < episodes; ++e) {
      const int length = 1 + static_cast<int>(make() % 12);  // episodes of unequal length
      for (int i = 0; i < length; ++i) ids.push_back(100 + 3 * e);
    }
    std::shuffle(ids.begin(), ids.end(), make);  // interleaved, as windows of several drives
    const Eigen::VectorXi episode = Eigen::Map<Eigen::VectorXi>(ids.data(), ids.size());
    std::mt19937_64 rng(seed);
    const std::vector<int> fold_of = EpisodeFolds(episode, folds, rng);
    ASSERT_EQ(fold_of.size(), ids.size());
    std::map<int, std::set<int>> folds_of_episode;
    std::vector<int> size(folds, 0);
    for (size_t i = 0; i < ids.size(); ++i) {
      ASSERT_GE(fold_of[i], 0);
      ASSERT_LT(fold_of[i], folds);
      folds_of_episode[ids[i]].insert(fold_of[i]);
      ++size[fold_of[i]];
    }
    for (const auto& [e, f] : folds_of_episode) EXPECT_EQ(f.size(), 1u) << "episode " << e;
    // Greedy smallest-fold deal: no fold empty, sizes within one episode length (<= 12).
    EXPECT_GT(*std::min_element(size.begin(), size.end()), 0);
    EXPECT_LE(
        *std::max_element(size.begin(), size.end()) - *std::min_element(size.begin(), size.end()),
        12);
  }
}

TEST(EpisodeFolds, CrossValidationUsesThemWhenTheSetHasEpisodes) {
  SampleSet set = test::MakeTerrainSet(3, 40, 1.0, 5);
  CvOptions options = SmallOptions();
  options.em_baseline = false;
  options.repeats = 1;
  EXPECT_NE(CrossValidate(set, options).folds_by.find("no episode data"), std::string::npos);
  set.episode.resize(set.size());
  set.step.resize(set.size());
  for (int i = 0; i < set.size(); ++i) set.episode(i) = i / 6, set.step(i) = i % 6;
  const CvSummary by_episode = CrossValidate(set, options);
  EXPECT_NE(by_episode.folds_by.find("whole episodes"), std::string::npos) << by_episode.folds_by;
  options.group_by_episode = false;
  EXPECT_NE(CrossValidate(set, options).folds_by.find("stratified"), std::string::npos);
}

TEST(StratifiedFolds, PartitionAndStratifyEveryCommand) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    std::mt19937_64 make(seed);
    const int n = 50 + static_cast<int>(make() % 200);
    const int folds = 2 + static_cast<int>(make() % 9);
    Eigen::VectorXi command(n);
    for (int i = 0; i < n; ++i) command(i) = static_cast<int>(make() % 7);
    std::mt19937_64 rng(seed);
    const std::vector<int> fold_of = StratifiedFolds(command, folds, rng);
    ASSERT_EQ(static_cast<int>(fold_of.size()), n);
    std::vector<int> fold_size(folds, 0);
    std::map<int, std::vector<int>> per_command;  // command -> count per fold
    for (int i = 0; i < n; ++i) {
      ASSERT_GE(fold_of[i], 0);
      ASSERT_LT(fold_of[i], folds);  // every sample in exactly one fold: a partition
      ++fold_size[fold_of[i]];
      per_command.try_emplace(command(i), folds, 0).first->second[fold_of[i]]++;
    }
    const auto [min_size, max_size] = std::minmax_element(fold_size.begin(), fold_size.end());
    EXPECT_LE(*max_size - *min_size, 1) << "seed " << seed;
    for (const auto& [c, counts] : per_command) {
      const auto [lo, hi] = std::minmax_element(counts.begin(), counts.end());
      EXPECT_LE(*hi - *lo, 1) << "command " << c << " seed " << seed;
    }
    std::mt19937_64 again(seed);
    EXPECT_EQ(StratifiedFolds(command, folds, again), fold_of);
  }
}

TEST(DeriveSeed, DistinctStreamsAndDeterministic) {
  std::set<std::uint64_t> seen;
  for (int r = 0; r < 10; ++r)
    for (int f = 0; f < 10; ++f) seen.insert(DeriveSeed(1, r, f, 1));
  EXPECT_EQ(seen.size(), 100u);
  EXPECT_EQ(DeriveSeed(3, 4, 5, 6), DeriveSeed(3, 4, 5, 6));
  EXPECT_NE(DeriveSeed(3, 4, 5, 6), DeriveSeed(4, 4, 5, 6));
}

TEST(CrossValidate, IdenticalForOneAndTwoThreads) {
  const SampleSet set = test::MakeTerrainSet(3, 20, 1.0, 11);
  CvOptions options = SmallOptions();
  options.threads = 1;
  const CvSummary one = CrossValidate(set, options);
  options.threads = 2;
  const CvSummary two = CrossValidate(set, options);
  for (auto member : {&CvSummary::dgmm_without_terrain, &CvSummary::dgmm_with_terrain,
                      &CvSummary::em_without_terrain, &CvSummary::em_with_terrain}) {
    ASSERT_TRUE((one.*member).evaluated);
    EXPECT_EQ((one.*member).per_fold, (two.*member).per_fold);
    EXPECT_EQ((one.*member).per_repeat, (two.*member).per_repeat);
    EXPECT_EQ((one.*member).standard_error, (two.*member).standard_error);
  }
  EXPECT_EQ(one.scored_per_repeat, set.size());
  EXPECT_EQ(one.unscored_per_repeat, 0);
  // The per-repeat totals are the sums of the fold totals, and the repeats differ (new folds).
  const CvScore& s = one.dgmm_with_terrain;
  ASSERT_EQ(static_cast<int>(s.per_repeat.size()), options.repeats);
  for (int r = 0; r < options.repeats; ++r)
    EXPECT_DOUBLE_EQ(s.per_fold.row(r).sum(), s.per_repeat[r]);
  EXPECT_NE(s.per_repeat[0], s.per_repeat[1]);
  EXPECT_GT(s.sd, 0);
  EXPECT_GT(s.standard_error, 0);
}

TEST(CrossValidate, TerrainHelpsWhenXDependsOnTerrain) {
  const SampleSet set = test::MakeTerrainSet(3, 40, 1.0, 3);
  const CvSummary cv = CrossValidate(set, SmallOptions());
  // x = mu + B z + 0.3 e with |B| ~ 1: knowing z shrinks the spread of x about threefold, a gain
  // of tens of nats per sample-dimension set; demand at least three standard errors.
  EXPECT_GT(cv.dgmm_with_terrain.mean,
            cv.dgmm_without_terrain.mean + 3 * cv.dgmm_without_terrain.standard_error);
  EXPECT_GT(cv.em_with_terrain.mean,
            cv.em_without_terrain.mean + 3 * cv.em_without_terrain.standard_error);
  // The change is the difference of the rows, its standard error that of the paired differences.
  for (const auto& [change, with, without] :
       {std::tuple{cv.dgmm_terrain_change, cv.dgmm_with_terrain, cv.dgmm_without_terrain},
        std::tuple{cv.em_terrain_change, cv.em_with_terrain, cv.em_without_terrain}}) {
    ASSERT_TRUE(change.evaluated);
    EXPECT_NEAR(change.mean, with.mean - without.mean, 1e-6 * std::abs(without.mean));
    EXPECT_GT(change.standard_error, 0);
    EXPECT_GT(change.mean, 3 * change.standard_error);
  }
}

TEST(CrossValidate, TerrainDoesNotHelpWhenXIgnoresTerrain) {
  const SampleSet set = test::MakeTerrainSet(3, 40, 0.0, 3);
  const CvSummary cv = CrossValidate(set, SmallOptions());
  // No information in z: conditioning can only add estimation noise. Allow one standard error
  // of the total (the spread another sample of the same size would show).
  EXPECT_LT(cv.dgmm_with_terrain.mean,
            cv.dgmm_without_terrain.mean + cv.dgmm_without_terrain.standard_error);
  EXPECT_LT(cv.em_with_terrain.mean,
            cv.em_without_terrain.mean + cv.em_without_terrain.standard_error);
  // Nor does the paired comparison, more sensitive, find a gain of two of its standard errors.
  EXPECT_LT(cv.dgmm_terrain_change.mean, 2 * cv.dgmm_terrain_change.standard_error);
  EXPECT_LT(cv.em_terrain_change.mean, 2 * cv.em_terrain_change.standard_error);
}

TEST(CrossValidate, FewerSamplesThanFoldsAndSingletonCommands) {
  SampleSet set = test::MakeTerrainSet(3, 4, 1.0, 5);  // 4 samples per command, 10 folds
  // Make command 2 a singleton: relabel three of its samples as command 0.
  int relabelled = 0;
  for (int i = 0; i < set.size() && relabelled < 3; ++i) {
    if (set.command(i) == 2) {
      set.command(i) = 0;
      ++relabelled;
    }
  }
  CvOptions options = SmallOptions();
  options.folds = 10;
  const CvSummary cv = CrossValidate(set, options);
  EXPECT_EQ(cv.unscored_per_repeat, 1);  // the singleton has no training sample when held out
  EXPECT_EQ(cv.scored_per_repeat, set.size() - 1);
  EXPECT_TRUE(std::isfinite(cv.dgmm_with_terrain.mean));
  // Three training samples of a command in d = 2 (5 parameters per Gaussian): no EM rows, and
  // the reason names the command and the counts.
  EXPECT_FALSE(cv.em_without_terrain.evaluated);
  EXPECT_FALSE(cv.em_with_terrain.evaluated);
  EXPECT_NE(cv.em_without_terrain_omitted.find("fewer than the 5 parameters"), std::string::npos)
      << cv.em_without_terrain_omitted;
  EXPECT_NE(cv.em_with_terrain_omitted.find("d = 4"), std::string::npos)
      << cv.em_with_terrain_omitted;
}

TEST(CrossValidate, EmRowsKeptWhenEveryCommandHasEnoughTrainingSamples) {
  const SampleSet set = test::MakeTerrainSet(2, 30, 1.0, 5);  // 24 training samples, 14 parameters
  const CvSummary cv = CrossValidate(set, SmallOptions());
  EXPECT_TRUE(cv.em_without_terrain.evaluated);
  EXPECT_TRUE(cv.em_with_terrain.evaluated);
  EXPECT_TRUE(cv.em_without_terrain_omitted.empty());
  EXPECT_TRUE(cv.em_with_terrain_omitted.empty());
}

TEST(CrossValidate, WithoutTerrainInTheSetSkipsTheTerrainRows) {
  SampleSet set = test::MakeTerrainSet(2, 15, 1.0, 5);
  set.z.resize(set.size(), 0);
  set.z_names.clear();
  set.z_units.clear();
  const CvSummary cv = CrossValidate(set, SmallOptions());
  EXPECT_FALSE(cv.has_terrain);
  EXPECT_TRUE(cv.dgmm_without_terrain.evaluated);
  EXPECT_FALSE(cv.dgmm_with_terrain.evaluated);
  EXPECT_FALSE(cv.em_with_terrain.evaluated);
  EXPECT_FALSE(cv.dgmm_terrain_change.evaluated);
}

TEST(CrossValidate, RejectsBadOptionsAndEmptySets) {
  const SampleSet set = test::MakeTerrainSet(2, 10, 1.0, 5);
  CvOptions options = SmallOptions();
  std::string error;
  options.dgmm.k = 0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(CrossValidate(set, options), InputError);
  options.dgmm.k = -1;
  EXPECT_THROW(CrossValidate(set, options), InputError);
  options = SmallOptions();
  options.folds = 1;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("folds"), std::string::npos);
  EXPECT_THROW(CrossValidate(set, options), InputError);
  options = SmallOptions();
  options.repeats = 0;
  EXPECT_THROW(CrossValidate(set, options), InputError);
  EXPECT_THROW(CrossValidate(set.Subset({}), SmallOptions()), InputError);
}

TEST(FitEmByBic, PrefersTwoComponentsForTwoClusters) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd Y(200, 2);
  for (int i = 0; i < 200; ++i) {
    const double shift = i < 100 ? -6.0 : 6.0;
    Y(i, 0) = shift + normal(rng);
    Y(i, 1) = normal(rng);
  }
  EmOptions em{.components = 1, .n_init = 2};
  int k = 0;
  const Mixture two = FitEmByBic(Y, em, 4, &k);
  EXPECT_EQ(k, 2);
  EXPECT_EQ(two.size(), 2);
  const Mixture one = FitEmByBic(Y.topRows(100), em, 4, &k);
  EXPECT_EQ(k, 1);
  // Never more free parameters than samples: K = 2 in 2-D has 11, so 10 points give K = 1.
  FitEmByBic(Y.middleRows(95, 10), em, 4, &k);
  EXPECT_EQ(k, 1);
}

}  // namespace
}  // namespace dgmm
