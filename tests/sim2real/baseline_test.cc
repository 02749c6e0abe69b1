// Stage 2 (locate): a planted friction is located on the slope, a null pair is not; the ceiling
// is above the sim model where the robot differs.
#include "sim2real/baseline.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

TEST(Baseline, LocatesAPlantedMismatchAndNotANullOne) {
  const test::Stages slip = test::RunStages({{test::kFriction, 0.5}}, 2);
  EXPECT_TRUE(slip.base.significant_mismatch);
  EXPECT_GT(slip.base.ll_ceiling, slip.base.ll_sim);
  EXPECT_EQ(slip.base.fold.size(), static_cast<size_t>(slip.in.real.size()));
  EXPECT_EQ(slip.base.before.heat.rows(), static_cast<int>(slip.in.real_commands.size()));
  EXPECT_EQ(slip.base.terrain_labels.size(), 3u);
  const test::Stages null = test::RunStages({}, 2);
  EXPECT_FALSE(null.base.significant_mismatch);
  EXPECT_TRUE(null.base.before.significant.empty());
}

// Rough ground: where a placement stands shapes all its executions. A null pair (two draws of
// places) is clean because locate then permutes whole placements; a planted friction is still
// located.
TEST(Baseline, OnRoughGroundANullPairIsCleanAndAPlantedOneLocated) {
  test::FakeSimulator rough;
  rough.ground_sd = 1.5;
  const test::Stages null = test::RunStages(rough, {}, 2);
  EXPECT_TRUE(null.base.placement.dependent);
  EXPECT_FALSE(null.base.significant_mismatch);
  const test::Stages slip = test::RunStages(rough, {{test::kFriction, 0.5}}, 2);
  EXPECT_TRUE(slip.base.placement.dependent);
  EXPECT_TRUE(slip.base.significant_mismatch);
  const test::Stages plane = test::RunStages({}, 2);
  EXPECT_FALSE(plane.base.placement.dependent);
  EXPECT_FALSE(plane.base.permute_placements);
}

// A simulator ground that is a height field permutes whole placements whatever the test says.
TEST(Baseline, AnUnevenGroundPermutesPlacements) {
  const test::FakeSimulator& fake = test::SharedFake();
  AnalysisOptions o = test::FastOptions(1);
  o.locate.uneven_ground = true;
  const test::FakePair pair = test::MakeFakePair(fake, {}, {});
  const Analysis a = Analyse(pair.sim, pair.real, nullptr, o, "locate only");
  EXPECT_FALSE(a.baseline.placement.dependent);
  EXPECT_TRUE(a.baseline.permute_placements);
  EXPECT_NE(a.baseline.permute_why.find("height field"), std::string::npos);
}

TEST(Baseline, LocateModelOfTheSimModelIsTheBaselinesOwn) {
  const test::Stages s = test::RunStages({{test::kFriction, 0.5}}, 2);
  std::mt19937_64 rng(5);
  const LocateSummary again = LocateModel(s.in, s.base, s.base.real_residuals, s.base.heldout_sim, true,
                                          s.options.locate.locate, rng);
  ASSERT_EQ(again.regions.size(), s.base.before.regions.size());
  EXPECT_EQ(again.heat, s.base.before.heat);  // deficits do not depend on the permutations
}

TEST(Baseline, WithoutTerrainTheHeatMapsColumnIsEachCommandsDeficit) {
  test::FakePair pair = test::MakeFakePair(test::SharedFake(), {{test::kFriction, 0.5}});
  for (SampleSet* set : {&pair.sim, &pair.real}) {
    set->z.resize(set->size(), 0);
    set->z_names.clear();
    set->z_units.clear();
  }
  const AnalysisInputs in = PrepareInputs(pair.sim, pair.real, 1);
  const Baseline base = LocateMismatch(in, test::FastOptions().locate);
  const Eigen::MatrixXd& heat = base.before.heat;
  ASSERT_EQ(heat.cols(), 1);
  ASSERT_EQ(heat.rows(), static_cast<int>(in.real_commands.size()));
  int filled = 0;
  for (const auto& r : base.before.regions) {
    if (r.family != "command") continue;
    const auto row = std::find(in.real_commands.begin(), in.real_commands.end(), r.command) - in.real_commands.begin();
    EXPECT_EQ(heat(row, 0), r.deficit) << r.label;
    ++filled;
  }
  EXPECT_EQ(filled, heat.rows());
  EXPECT_GT(heat.cwiseAbs().maxCoeff(), 0) << "not an empty column";
}

}  // namespace
}  // namespace dgmm::sim2real
