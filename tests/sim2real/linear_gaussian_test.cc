// The linear-Gaussian reference model: recovers a planted linear map, predictive covariance
// larger than the residual one, prior strength interpolates between real-only and the prior.
#include "sim2real/linear_gaussian.h"

#include <gtest/gtest.h>

#include "tests/sim2real/synthetic.h"

namespace dgmm::sim2real {
namespace {

Samples Make(const SyntheticWorld& w, const std::string& protocol, std::uint64_t seed) {
  return MakeSamples(GenerateSynthetic(w, protocol, seed));
}

TEST(LinearGaussianModel, HeldOutLikelihoodBeatsAShiftedTruth) {
  Samples train = Make(SyntheticWorld{}, "paper-830", 1);
  Samples test = Make(SyntheticWorld{}, "paper", 2);
  SyntheticWorld shifted;
  shifted.bias = (Eigen::VectorXd(6) << 0.02, 0, 0, 0, 0, 0).finished();
  Samples other = Make(shifted, "paper", 2);
  LinearGaussianModel m = LinearGaussianModel::Fit(train, LinearGaussianOptions{});
  // The same physics scores better than physics shifted by ~2 noise sd in dx.
  EXPECT_GT(m.LogLikelihood(test).mean(), m.LogLikelihood(other).mean() + 0.5);
}

TEST(LinearGaussianModel, PredictionsAreCalibrated) {
  Samples train = Make(SyntheticWorld{}, "paper-830", 3);
  Samples test = Make(SyntheticWorld{}, "paper", 4);
  LinearGaussianModel m = LinearGaussianModel::Fit(train, LinearGaussianOptions{});
  Eigen::MatrixXd r = m.WhitenedResiduals(test);
  // Whitened held-out residuals ~ N(0, I): mean square per entry near 1 (390 x 6 entries; the
  // bound allows the shrinkage's bias and sampling error).
  const double ms = r.squaredNorm() / r.size();
  EXPECT_GT(ms, 0.75);
  EXPECT_LT(ms, 1.25);
}

TEST(LinearGaussianModel, ResidualsWhitenToTheWhitenedResiduals) {
  Samples train = Make(SyntheticWorld{}, "paper-830", 7);
  Samples test = Make(SyntheticWorld{}, "paper", 8);
  LinearGaussianModel m = LinearGaussianModel::Fit(train, LinearGaussianOptions{});
  const Eigen::MatrixXd r = m.Residuals(test), w = m.WhitenedResiduals(test);
  ASSERT_EQ(r.rows(), test.size());
  for (int i : {0, test.size() / 2, test.size() - 1}) {
    const Prediction p = m.Predict(test.command[i], test.z.row(i).transpose(), test.first_execution[i]);
    EXPECT_LT((p.chol.triangularView<Eigen::Lower>() * w.row(i).transpose() - r.row(i).transpose()).norm(), 1e-9);
    EXPECT_LT((test.x.row(i).transpose() - p.mean - r.row(i).transpose()).norm(), 1e-12);
  }
}

TEST(LinearGaussianModel, StrongPriorReproducesThePrior) {
  Samples sim = Make(SyntheticWorld{}, "paper-830", 5);
  Samples real = Make(SyntheticWorld{}, "paper", 6);
  LinearGaussianModel prior = LinearGaussianModel::Fit(sim, LinearGaussianOptions{});
  LinearGaussianModel strong =
      LinearGaussianModel::FitWithPrior(real, LinearGaussianOptions{}, {}, prior, 1e6);
  Eigen::VectorXd z = real.z.row(0).transpose();
  EXPECT_LT((strong.Predict(real.command[0], z).mean - prior.Predict(real.command[0], z).mean)
                .cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace dgmm::sim2real
