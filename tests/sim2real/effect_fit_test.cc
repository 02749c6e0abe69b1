// The Ceres maximum-likelihood fit against closed forms: with mean effects only, theta is the
// least-squares solution of the whitened problem; with the noise effect, tau^2 = RSS / (n dx).
#include "sim2real/effect_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
  f.sim = MakeSamples(sim);
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

// A knob whose recording both shifts the mean (raw design d) and widens the spread (log-variance
// ratio v per axis) at coefficient 1: real residuals theta* d + S L u, S = diag(exp(theta* v / 2)).
// With the spread signature the fit recovers theta* from both, and the likelihood is the
// Gaussian density of N(theta d, S Sigma S).
FitProblem SpreadCase(double theta, const Eigen::Vector3d& v, int n, std::uint64_t seed) {
  FitProblem fp;
  fp.n = n;
  fp.dx = 3;
  EffectSpec s;
  s.key = "knob";
  s.parameters = {{"t", ""}};
  fp.library = {s};
  Eigen::Matrix3d l;
  l << 0.02, 0, 0, 0.01, 0.03, 0, -0.004, 0.006, 0.01;
  const Eigen::Vector3d sd = (0.5 * theta * v).array().exp();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd d(n * 3, 1), g(n * 3, 1);
  fp.r0.resize(n, 3);
  fp.raw.resize(n, 3);
  fp.log_norm = Eigen::VectorXd::Constant(n, -0.5 * (3 * std::log(2 * M_PI) + 2 * std::log(l.diagonal().prod())));
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d raw_d(0.01 * std::sin(0.1 * i), 0.005, 0.01 * std::cos(0.3 * i));
    const Eigen::Vector3d u(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3d raw = theta * raw_d + sd.cwiseProduct(l * u);
    d.middleRows(i * 3, 3) = raw_d;
    g.middleRows(i * 3, 3) = l.triangularView<Eigen::Lower>().solve(raw_d);
    fp.raw.row(i) = raw.transpose();
    fp.r0.row(i) = l.triangularView<Eigen::Lower>().solve(raw).transpose();
    fp.episode.push_back(i / 10);
    fp.command.push_back(0);
    fp.chol.push_back(l);
  }
  fp.d = {d};
  fp.g = {g};
  fp.log_var = {v};
  return fp;
}

TEST(EffectFit, ASpreadSignatureScalesTheCovarianceWithTheCoefficient) {
  const Eigen::Vector3d v(1.2, 0.0, -0.6);
  const FitProblem fp = SpreadCase(1.5, v, 3000, 7);
  const EffectFit fit = FitEffects(fp, {0}, {});
  ASSERT_TRUE(fit.converged);
  EXPECT_NEAR(fit.theta[0](0), 1.5, 0.08);
  ASSERT_EQ(fit.log_var.size(), 3);
  EXPECT_NEAR((fit.log_var - fit.theta[0](0) * v).norm(), 0.0, 1e-9);
  // Without the spread signature the mean alone is fitted, and the likelihood is lower.
  FitProblem mean_only = fp;
  mean_only.log_var = {Eigen::VectorXd()};
  const EffectFit plain = FitEffects(mean_only, {0}, {});
  EXPECT_EQ(plain.log_var.size(), 0);
  EXPECT_GT(fit.train_log_likelihood, plain.train_log_likelihood + 100);
  // The likelihood is the density of N(theta d, S Sigma S) (brute force for a few rows).
  const Eigen::VectorXd ll = CorrectedLogLikelihood(fp, fit, {0, 1, 2});
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d s_half = (0.5 * fit.log_var).array().exp();
    const Eigen::Matrix3d cov = s_half.asDiagonal() * fp.chol[i] * fp.chol[i].transpose() * s_half.asDiagonal();
    const Eigen::Vector3d r = fp.raw.row(i).transpose() - fp.d[0].middleRows(i * 3, 3) * fit.theta[0];
    const double want = -0.5 * (3 * std::log(2 * M_PI) + std::log(cov.determinant()) + r.dot(cov.ldlt().solve(r)));
    EXPECT_NEAR(ll(i), want, 1e-8) << "row " << i;
  }
}

// Spreads beyond max_log_ratio are clamped: the fit stays finite and the log ratio at the bound.
TEST(EffectFit, ASpreadSignatureIsClampedAtTheMaximumLogRatio) {
  FitProblem fp = SpreadCase(3.0, Eigen::Vector3d(1.5, 0.0, 0.0), 800, 8);
  fp.max_log_ratio = 2.0;
  const EffectFit fit = FitEffects(fp, {0}, {});
  ASSERT_EQ(fit.log_var.size(), 3);
  EXPECT_LE(fit.log_var.cwiseAbs().maxCoeff(), 2.0 + 1e-12);
  EXPECT_TRUE(std::isfinite(fit.train_log_likelihood));
}

}  // namespace
}  // namespace dgmm::sim2real
