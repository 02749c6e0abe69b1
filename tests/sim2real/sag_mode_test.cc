// A recording's sags as a mode of their own (sag_mode.h): counted against a reference that saw
// none of them, fitted with their share and direction, and scoring real samples that sag the same
// way higher than a recording that sags another way or not at all.
#include "sim2real/sag_mode.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/sim2real/synthetic.h"

namespace dgmm::sim2real {
namespace {

Samples World(std::uint64_t seed) { return MakeSamples(GenerateSynthetic(SyntheticWorld{}, "paper", seed)); }

// Every `every`-th sample moved by `shift` (a sag: far beyond the noise).
Samples Sag(Samples s, const Eigen::VectorXd& shift, int every, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> jitter(0.0, 0.1);
  for (int i = 0; i < s.size(); i += every) {
    for (int k = 0; k < s.pose_dim(); ++k) s.x(i, k) += shift(k) * (1 + jitter(rng));
  }
  return s;
}

Eigen::VectorXd Down(double roll) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(6);
  v(2) = -0.05, v(3) = roll;  // dz, droll
  return v;
}

TEST(SagMode, CountsAndFitsTheRecordingsOwnSags) {
  const SagReference ref = MakeSagReference(World(1), {});
  const SagModel plain = FitSagModel(World(2), {}, ref, {}, {});
  EXPECT_LT(plain.share, 0.02) << "a recording like the reference barely sags";
  const Samples sagging = Sag(World(2), Down(0.2), 10, 3);
  const SagModel m = FitSagModel(sagging, {}, ref, {}, {});
  EXPECT_NEAR(m.share, 0.1, 0.03);
  EXPECT_NEAR(m.sag.mean()(3), 0.2, 0.03) << "the sags' direction";
  EXPECT_NEAR(m.sag.mean()(2), -0.05, 0.01);
}

TEST(SagMode, RealSagsFavourTheRecordingThatSagsTheSameWay) {
  const SagReference ref = MakeSagReference(World(1), {});
  const SagModel none = FitSagModel(World(2), {}, ref, {}, {});
  const SagModel left = FitSagModel(Sag(World(3), Down(0.2), 10, 4), {}, ref, {}, {});
  const SagModel right = FitSagModel(Sag(World(3), Down(-0.2), 10, 4), {}, ref, {}, {});
  const Samples real = Sag(World(5), Down(0.2), 10, 6);
  const double l_none = SagLogLikelihood(none, ref, real, {}).mean();
  const double l_left = SagLogLikelihood(left, ref, real, {}).mean();
  const double l_right = SagLogLikelihood(right, ref, real, {}).mean();
  EXPECT_GT(l_left, l_none + 0.1);
  EXPECT_GT(l_left, l_right + 0.1);
  // Without sags in the real samples, the recording that never sags fits them best.
  const Samples calm = World(7);
  EXPECT_GT(SagLogLikelihood(none, ref, calm, {}).mean(), SagLogLikelihood(left, ref, calm, {}).mean());
}

TEST(SagMode, AFallNoRecordingMadeCostsFiniteNats) {
  const SagReference ref = MakeSagReference(World(1), {});
  const SagModel none = FitSagModel(World(2), {}, ref, {}, {});
  Samples real = World(5);
  real.x.row(0) *= 1e3;
  const Eigen::VectorXd l = SagLogLikelihood(none, ref, real, {});
  EXPECT_TRUE(l.allFinite());
  EXPECT_LT(l(0), l(1));
}

}  // namespace
}  // namespace dgmm::sim2real
