// Rows grouped into units (units.h): dense ids by first appearance or by ascending label, and the
// rows of each unit.
#include "sim2real/units.h"

#include <gtest/gtest.h>

namespace dgmm::sim2real {
namespace {

TEST(Units, IdsFollowFirstAppearance) {
  const UnitIds u = NumberUnits({7, 7, 3, 9, 3, 7});
  EXPECT_EQ(u.count, 3);
  EXPECT_EQ(u.unit, (std::vector<int>{0, 0, 1, 2, 1, 0}));
}

TEST(Units, AscendingIdsFollowTheLabelsOrder) {
  const UnitIds u = NumberUnitsAscending({7, 7, 3, 9, 3, 7});
  EXPECT_EQ(u.count, 3);
  EXPECT_EQ(u.unit, (std::vector<int>{1, 1, 0, 2, 0, 1}));
}

TEST(Units, RowsOfEachUnitInOrder) {
  const std::vector<std::vector<int>> rows = RowsOfUnits(NumberUnitsAscending({7, 7, 3, 9, 3, 7}));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0], (std::vector<int>{2, 4}));
  EXPECT_EQ(rows[1], (std::vector<int>{0, 1, 5}));
  EXPECT_EQ(rows[2], (std::vector<int>{3}));
  EXPECT_TRUE(RowsOfUnits(NumberUnits({})).empty());
}

}  // namespace
}  // namespace dgmm::sim2real
