#include "core/log_sum_exp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace dgmm {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(LogSumExp, MatchesTheDirectSumWhereThatIsRepresentable) {
  const std::vector<double> v = {-1.5, 0.25, 2.0, -3.0};
  double direct = 0;
  for (double x : v) direct += std::exp(x);
  EXPECT_NEAR(LogSumExp(v.data(), 4), std::log(direct), 1e-12);
  EXPECT_NEAR(LogSumExp(Eigen::Map<const Eigen::VectorXd>(v.data(), 4)), std::log(direct), 1e-12);
}

TEST(LogSumExp, StaysFiniteFarOutsideTheExponentsRange) {
  // exp(-2000) and exp(2000) are 0 and inf in double; the shifted sum is not.
  const std::vector<double> low = {-2000.0, -2000.0}, high = {2000.0, 2000.0};
  EXPECT_NEAR(LogSumExp(low.data(), 2), -2000.0 + std::log(2.0), 1e-9);
  EXPECT_NEAR(LogSumExp(high.data(), 2), 2000.0 + std::log(2.0), 1e-9);
}

TEST(LogSumExp, EmptyAndAllMinusInfinityAreMinusInfinity) {
  EXPECT_EQ(LogSumExp(nullptr, 0), -kInf);
  const std::vector<double> v = {-kInf, -kInf};
  EXPECT_EQ(LogSumExp(v.data(), 2), -kInf);
  const std::vector<double> w = {-kInf, 1.0};
  EXPECT_DOUBLE_EQ(LogSumExp(w.data(), 2), 1.0);
}

TEST(LogSumExp, PropagatesInfinityAndNan) {
  const std::vector<double> inf = {1.0, kInf}, nan = {1.0, std::nan("")};
  EXPECT_EQ(LogSumExp(inf.data(), 2), kInf);
  EXPECT_TRUE(std::isnan(LogSumExp(nan.data(), 2)));
}

TEST(LogSumExp, TermFormAgreesWithTheBufferFormAndCallsEachTermTwice) {
  const std::vector<double> v = {-1.5, 0.25, 2.0, -3.0, 700.0};
  std::vector<int> calls(v.size(), 0);
  const double streamed = LogSumExpOf(static_cast<int>(v.size()), [&](int i) {
    ++calls[i];
    return v[i];
  });
  EXPECT_EQ(streamed, LogSumExp(v.data(), static_cast<int>(v.size())));
  for (int c : calls) EXPECT_EQ(c, 2);
}

}  // namespace
}  // namespace dgmm
