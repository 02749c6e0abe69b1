// The Ceres maximum-likelihood fit against closed forms: with mean effects only, theta is the
// least-squares solution of the whitened problem; with the noise effect, tau^2 = RSS / (n dx).
#include "sim2real/effect_fit.h"

#include <gtest/gtest.h>

#include "sim2real/knob_design.h"
#include "tests/sim2real/synthetic.h"

namespace dgmm::sim2real {
namespace {

struct Fixture {
  Samples sim, real;
  LinearGaussianModel model;
  FitProblem problem;
};

Fixture Make() {
  Fixture f;
  SyntheticWorld w;
  w.asymmetry_yaw_per_execution = 0.02;
  w.slip_creep = 0.03;
  SampleSet sim = GenerateSynthetic(SyntheticWorld{}, "paper-830", 3);
  SampleSet real = GenerateSynthetic(w, "paper", 4);
  std::vector<int> id(sim.num_commands());
  for (int c = 0; c < sim.num_commands(); ++c) id[c] = c;
  f.sim = MakeSamples(sim, id);
  f.real = MakeSamples(real, AlignCommands(sim, real));
  f.model = LinearGaussianModel::Fit(f.sim, LinearGaussianOptions{});
  // Designs: a constant offset (tracker bias), a yaw per execution (heading drift), the sim
  // model's terrain slopes (IMU bias) and the noise scale.
  const PoseLayout layout = DetectPoseLayout(sim);
  const std::vector<ExternalCandidate> designs = {{ExternalCandidate::kTrackerBias, {}},
                                                  {ExternalCandidate::kHeading, {}},
                                                  {ExternalCandidate::kImuBias, {}}};
  std::vector<EffectSpec> library = {ExternalSpec("bias", "bias", 5, "x units"), ExternalSpec("heading", "yaw", 1, "rad"),
                                     ExternalSpec("imu", "imu", 2, "rad"), NoiseEffect()};
  f.problem = MakeFitProblem(f.real, f.model, library);
  for (int k = 0; k < 3; ++k) {
    for (int i = 0; i < f.real.size(); ++i) {
      SetDesign(&f.problem, k, i,
                ExternalDesign(designs[k], {}, f.model, layout, 6, f.real.command[i], f.real.z.row(i).transpose(),
                               f.real.first_execution[i]));
    }
  }
  return f;
}

int IndexOf(const FitProblem& p, const std::string& key) {
  for (size_t k = 0; k < p.library.size(); ++k)
    if (p.library[k].key == key) return static_cast<int>(k);
  return -1;
}

// Relative agreement of a Ceres optimum with the closed form (L-BFGS stops on tolerances).
constexpr double kRelativeTolerance = 1e-4;

TEST(EffectFit, MeanEffectsEqualLeastSquares) {
  Fixture f = Make();
  for (const std::string key : {"bias", "heading", "imu"}) {
    const int e = IndexOf(f.problem, key);
    ASSERT_GE(e, 0) << key;
    EffectFit fit = FitEffects(f.problem, {e}, {});
    EXPECT_TRUE(fit.converged);
    Eigen::VectorXd r0 = Eigen::Map<const Eigen::VectorXd>(
        Eigen::MatrixXd(f.problem.r0.transpose()).data(), f.problem.n * f.problem.dx);
    const Eigen::MatrixXd& g = f.problem.g[e];
    Eigen::VectorXd ls = g.colPivHouseholderQr().solve(r0);
    const double rss_ls = (r0 - g * ls).squaredNorm();
    const double rss_fit = (r0 - g * fit.theta[0]).squaredNorm();
    EXPECT_LE(rss_fit, rss_ls * (1 + kRelativeTolerance)) << key;
  }
}

TEST(EffectFit, NoiseScaleIsRootMeanSquare) {
  Fixture f = Make();
  const int e = IndexOf(f.problem, "tracker_noise");
  EffectFit fit = FitEffects(f.problem, {e}, {});
  const double rms = std::sqrt(f.problem.r0.squaredNorm() / (f.problem.n * f.problem.dx));
  EXPECT_NEAR(std::exp(fit.log_tau), rms, kRelativeTolerance * rms * 10);
}

TEST(EffectFit, CorrectedLikelihoodNeverBelowSimAtTheOptimum) {
  Fixture f = Make();
  const double base = CorrectedLogLikelihood(f.problem, EffectFit{}).sum();
  for (size_t e = 0; e < f.problem.library.size(); ++e) {
    EffectFit fit = FitEffects(f.problem, {static_cast<int>(e)}, {});
    EXPECT_GE(fit.train_log_likelihood, base - 1e-6) << f.problem.library[e].key;
  }
}

}  // namespace
}  // namespace dgmm::sim2real
