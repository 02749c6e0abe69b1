#include "sim2real/spread.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sim2real/selection.h"

namespace dgmm::sim2real {
namespace {

// n samples in dx = 3 with a correlated sim covariance Sigma = L L^T, one mean-shift effect with
// raw design d, and raw real residuals theta d + S L u (u ~ N(0, I), S = diag(sqrt(rho))), whose
// covariance is S Sigma S. The caller re-points sp.fit at its own copy of fp.
struct Case {
  FitProblem fp;
  SpreadProblem sp;
  std::vector<int> rows, fold;
};

Case MakeCase(const Eigen::Vector3d& rho, double theta, std::uint64_t seed, int n = 1200) {
  Case c;
  FitProblem& fp = c.fp;
  fp.n = n;
  fp.dx = 3;
  EffectSpec s;
  s.id = EffectId::kExternal;
  s.key = "knob";
  s.parameters = {{"t", ""}};
  fp.library.push_back(s);
  Eigen::Matrix3d l;
  l << 1.0, 0, 0, 0.4, 0.9, 0, -0.2, 0.3, 0.7;
  const Eigen::Vector3d sd = rho.cwiseSqrt();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd d(n * 3, 1), g(n * 3, 1);
  fp.r0.resize(n, 3);
  fp.log_norm = Eigen::VectorXd::Constant(n, -0.5 * (3 * std::log(2 * M_PI) + 2 * std::log(l.diagonal().prod())));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d raw_d(std::sin(0.1 * i), 0.5, std::cos(0.3 * i));
    Eigen::Vector3d u(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d raw = theta * raw_d + sd.cwiseProduct(l * u);
    d.middleRows(i * 3, 3) = raw_d;
    g.middleRows(i * 3, 3) = l.triangularView<Eigen::Lower>().solve(raw_d);
    fp.r0.row(i) = l.triangularView<Eigen::Lower>().solve(raw).transpose();
    fp.episode.push_back(i / 10);
    fp.command.push_back((i / 10) % 4);
    fp.chol.push_back(l);
  }
  fp.d = {d};
  fp.g = {g};
  c.sp.fit = &c.fp;
  c.sp.log_var = {Eigen::VectorXd()};
  c.sp.tracker = Eigen::Vector3d(1.0, 1.0, 0.2);
  c.sp.a_lo = -0.25, c.sp.a_hi = 8;
  for (int i = 0; i < n; ++i) c.rows.push_back(i);
  std::mt19937_64 frng(1);
  c.fold = MakeFolds(fp, c.rows, 5, frng);
  return c;
}

// The likelihood with rho = 1 is the whitened Gaussian's; a wider rho lowers it on unit data.
TEST(SpreadLogLikelihood, UnitRatioIsTheSimModel) {
  Case c = MakeCase(Eigen::Vector3d::Ones(), 0.0, 3, 200);
  c.sp.fit = &c.fp;
  EffectFit none;
  const Eigen::VectorXd ll = SpreadLogLikelihood(c.sp, none, Eigen::Vector3d::Ones(), c.rows);
  for (int i = 0; i < 200; ++i) {
    EXPECT_NEAR(ll(i), c.fp.log_norm(i) - 0.5 * c.fp.r0.row(i).squaredNorm(), 1e-9);
  }
  EXPECT_LT(SpreadLogLikelihood(c.sp, none, Eigen::Vector3d::Constant(4.0), c.rows).sum(), ll.sum());
}

// Tracker-shaped extra variance (rho = 1 + a T, a = 2) is found, with a recovered to 15%.
TEST(TestTrackerSpread, FindsTrackerShapedSpread) {
  Case c = MakeCase(Eigen::Vector3d(3.0, 3.0, 1.4), 0.5, 7);
  c.sp.fit = &c.fp;
  const SpreadTest t = TestTrackerSpread(c.sp, {0}, c.rows, c.fold, {}, {});
  ASSERT_TRUE(t.tested);
  EXPECT_TRUE(t.tracker_needed);
  EXPECT_NEAR(t.a, 2.0, 0.3);
  EXPECT_GT(t.z, 3);
}

// The same wider spread, made by the knob in simulation (its log-variance signature at theta 1):
// the tracker noise adds nothing held out, and is not needed.
TEST(TestTrackerSpread, KnobSpreadLeavesNoRoomForTheTracker) {
  int needed = 0;
  for (int seed = 0; seed < 10; ++seed) {
    Case c = MakeCase(Eigen::Vector3d(3.0, 3.0, 1.4), 1.0, 100 + seed);
    c.sp.fit = &c.fp;
    c.sp.log_var = {Eigen::Vector3d(std::log(3.0), std::log(3.0), std::log(1.4))};
    const SpreadTest t = TestTrackerSpread(c.sp, {0}, c.rows, c.fold, {}, {});
    EXPECT_NEAR(t.knob_log_ratio(0), std::log(3.0), 0.1);
    needed += t.tracker_needed;
  }
  EXPECT_LE(needed, 2);
}

// The sim model's own spread: the tracker is needed in few of 20 data sets (one-sided 5% test).
TEST(TestTrackerSpread, NullSpreadRarelyNeedsTheTracker) {
  int needed = 0;
  for (int seed = 0; seed < 20; ++seed) {
    Case c = MakeCase(Eigen::Vector3d::Ones(), 0.5, 200 + seed);
    c.sp.fit = &c.fp;
    needed += TestTrackerSpread(c.sp, {0}, c.rows, c.fold, {}, {}).tracker_needed;
  }
  EXPECT_LE(needed, 3);
}

// No tracker knob: nothing tested.
TEST(TestTrackerSpread, WithoutATrackerKnobNothingIsTested) {
  Case c = MakeCase(Eigen::Vector3d::Ones(), 0.0, 5, 100);
  c.sp.fit = &c.fp;
  c.sp.tracker.resize(0);
  EXPECT_FALSE(TestTrackerSpread(c.sp, {0}, c.rows, c.fold, {}, {}).tested);
}

}  // namespace
}  // namespace dgmm::sim2real
