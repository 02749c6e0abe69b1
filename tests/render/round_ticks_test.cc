#include "render/round_ticks.h"

#include <gtest/gtest.h>

#include <cmath>

#include <string>
#include <vector>

namespace dgmm {
namespace {

std::vector<std::string> Labels(double lo, double hi, int max_ticks) {
  std::vector<std::string> out;
  for (const Tick& t : RoundTicks(lo, hi, max_ticks)) out.push_back(t.label);
  return out;
}

TEST(RoundTicks, StepsOfOneTwoTwoAndAHalfOrFiveWithJustTheDecimalsNeeded) {
  // 0.64 wide, at most 10: raw 0.064 -> step 0.1, one decimal, zero not "-0.0".
  EXPECT_EQ(Labels(-0.37, 0.27, 10),
            (std::vector<std::string>{"-0.3", "-0.2", "-0.1", "0.0", "0.1", "0.2"}));
  // 0.2 wide, at most 10: raw 0.02 -> step 0.02 (2 x 10^-2), two decimals.
  EXPECT_EQ(Labels(0.225, 0.425, 10),
            (std::vector<std::string>{"0.24", "0.26", "0.28", "0.30", "0.32", "0.34", "0.36",
                                      "0.38", "0.40", "0.42"}));
  // 0.22 wide: raw 0.022 -> step 0.025, three decimals.
  EXPECT_EQ(Labels(0.2, 0.42, 10),
            (std::vector<std::string>{"0.200", "0.225", "0.250", "0.275", "0.300", "0.325",
                                      "0.350", "0.375", "0.400"}));
  // 2.5 with e = 1 needs no decimal; 2.5 with e = 0 needs one.
  EXPECT_EQ(Labels(0, 100, 4), (std::vector<std::string>{"0", "25", "50", "75", "100"}));
  EXPECT_EQ(Labels(0, 10, 4), (std::vector<std::string>{"0.0", "2.5", "5.0", "7.5", "10.0"}));
  // raw 0.95 -> step 1 (10 x 10^-1 becomes 1 x 10^0): no decimals.
  EXPECT_EQ(Labels(0.05, 3.85, 4), (std::vector<std::string>{"1", "2", "3"}));
}

TEST(RoundTicks, ValuesLieInsideTheRangeAndNoMoreThanTwiceTheRequestedCount) {
  for (double width : {1e-9, 3e-4, 0.7, 13.0, 4.2e6}) {
    const auto ticks = RoundTicks(-0.3 * width, 0.7 * width, 8);
    ASSERT_FALSE(ticks.empty()) << width;
    EXPECT_LE(ticks.size(), 17u) << width;
    for (const Tick& t : ticks) {
      EXPECT_GE(t.value, -0.3 * width * (1 + 1e-9)) << width;
      EXPECT_LE(t.value, 0.7 * width * (1 + 1e-9)) << width;
    }
  }
}

TEST(RoundTicks, EmptyRangeOrNonFiniteGivesNoTicks) {
  EXPECT_TRUE(RoundTicks(1, 1, 5).empty());
  EXPECT_TRUE(RoundTicks(2, 1, 5).empty());
  EXPECT_TRUE(RoundTicks(0, INFINITY, 5).empty());
  EXPECT_TRUE(RoundTicks(NAN, 1, 5).empty());
}

}  // namespace
}  // namespace dgmm
