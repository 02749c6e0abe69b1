#include "tune/dimensions.h"

#include <gtest/gtest.h>

#include "tests/tune/synthetic.h"
#include "util/error.h"

namespace dgmm {
namespace {

TEST(SelectDimensions, PicksNamedColumnsInTheGivenOrder) {
  SampleSet set = test::MakeTerrainSet(2, 5, 1.0, 1);
  set.transform.offset = Eigen::Vector4d(1, 2, 3, 4);
  set.transform.scale = Eigen::Vector4d(10, 20, 30, 40);
  const SampleSet out = SelectDimensions(set, {"dy", "dx"}, {"roll"});
  ASSERT_EQ(out.pose_dim(), 2);
  ASSERT_EQ(out.terrain_dim(), 1);
  EXPECT_EQ(out.x_names, (std::vector<std::string>{"dy", "dx"}));
  EXPECT_EQ(out.z_names, (std::vector<std::string>{"roll"}));
  EXPECT_EQ(out.x.col(0), set.x.col(1));
  EXPECT_EQ(out.x.col(1), set.x.col(0));
  EXPECT_EQ(out.z.col(0), set.z.col(1));
  // y = x || z: the transform follows the same columns (dy, dx, roll).
  EXPECT_EQ(out.transform.offset, Eigen::Vector3d(2, 1, 4));
  EXPECT_EQ(out.transform.scale, Eigen::Vector3d(20, 10, 40));
  EXPECT_TRUE(out.Validate().empty()) << out.Validate();
}

TEST(SelectDimensions, EmptyListsKeepEverythingAndUnknownNamesAreInputErrors) {
  const SampleSet set = test::MakeTerrainSet(2, 5, 1.0, 1);
  const SampleSet same = SelectDimensions(set, {}, {});
  EXPECT_EQ(same.x, set.x);
  EXPECT_EQ(same.z, set.z);
  try {
    SelectDimensions(set, {"dtheta"}, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dtheta"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("dx, dy"), std::string::npos);
  }
}

}  // namespace
}  // namespace dgmm
