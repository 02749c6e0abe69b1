// The model files of the analysis (sim2real/corrected_model.h) must carry the analysis' models:
// their conditional p(x | c, z) equals the analysis' prediction mixed over the first-execution
// flag (the one thing a file cannot condition on), and they score the real data as the analysis
// does.
#include "sim2real/corrected_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "sim2real/effect_fit.h"
#include "tests/sim2real/fake_simulator.h"
#include "tests/sim2real/synthetic.h"

namespace dgmm::sim2real {
namespace {

// The analysis of a fake pair with a friction and a latency (first executions differ from repeats).
struct Pair {
  SampleSet sim, real;
  Samples real_samples;
  Analysis a;
};

const Pair& SlipPair() {
  static const Pair pair = [] {
    static const test::FakeSimulator fake;
    const test::FakePair fp = test::MakeFakePair(fake, {{test::kFriction, 0.6}, {test::kLatency, 0.03}});
    AnalysisOptions options = test::FastOptions();
    options.refine.selection.bootstrap_selection = 0;
    options.refine.selection.bootstrap_parameters = 0;
    Pair p;
    p.a = Analyse(fp.sim, fp.real, &fake, options);
    p.sim = p.a.inputs.sim_set;
    p.real = p.a.inputs.real_set;
    p.real_samples = p.a.inputs.real;
    return p;
  }();
  return pair;
}

MotionModel Corrected(const Pair& p, const CorrectedModelOptions& options = {}) {
  return BuildCorrectedModel(p.a.baseline.sim_model, p.a.correction, p.a.inputs.first_execution_share, p.sim, options);
}
MotionModel Sim(const Pair& p, const CorrectedModelOptions& options = {}) {
  return BuildSimModel(p.a.baseline.sim_model, p.a.inputs.first_execution_share, p.sim, options);
}

double LogNormalDensity(const Eigen::VectorXd& x, const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov) {
  Eigen::LLT<Eigen::MatrixXd> llt(cov);
  const Eigen::MatrixXd l = llt.matrixL();
  const Eigen::VectorXd r = l.triangularView<Eigen::Lower>().solve(x - mean);
  return -0.5 * (x.size() * std::log(2 * std::numbers::pi) + r.squaredNorm()) -
         l.diagonal().array().log().sum();
}

// The analysis' prediction at (c, z) for each first-execution flag f: weight (the real share of
// f), mean u + sum_e D_e(u, g(z), f) theta_e and covariance tau^2 Sigma_c(z, f).
struct FlagCase {
  double weight;
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
};
std::vector<FlagCase> AnalysisPrediction(const Analysis& r, bool corrected, int c, const Eigen::VectorXd& z) {
  const double tau2 = corrected ? std::exp(2 * r.correction.log_tau) : 1.0;
  std::vector<FlagCase> cases;
  for (int first = 0; first < 2; ++first) {
    const Prediction p = r.baseline.sim_model.Predict(c, z, first);
    Eigen::VectorXd mean = p.mean;
    if (corrected) mean += r.correction.Shift(c, z, first, static_cast<int>(mean.size()));
    const double share = first ? r.inputs.first_execution_share : 1 - r.inputs.first_execution_share;
    cases.push_back({share, mean, tau2 * p.chol * p.chol.transpose()});
  }
  return cases;
}

// The analysis' density of x at (c, z), its flag unknown: log sum_f share_f N(x; mean_f, cov_f).
double AnalysisLogDensity(const Analysis& r, bool corrected, int c, const Eigen::VectorXd& x,
                          const Eigen::VectorXd& z) {
  std::vector<double> log_p;
  for (const FlagCase& f : AnalysisPrediction(r, corrected, c, z)) {
    log_p.push_back(std::log(f.weight) + LogNormalDensity(x, f.mean, f.cov));
  }
  const double top = std::max(log_p[0], log_p[1]);
  return top + std::log(std::exp(log_p[0] - top) + std::exp(log_p[1] - top));
}

// A draw of x from the analysis' flag-mixed prediction at (c, z).
Eigen::VectorXd AnalysisDraw(const Analysis& r, bool corrected, int c, const Eigen::VectorXd& z,
                             std::mt19937_64& rng) {
  const std::vector<FlagCase> cases = AnalysisPrediction(r, corrected, c, z);
  const FlagCase& f = std::bernoulli_distribution(cases[1].weight)(rng) ? cases[1] : cases[0];
  std::normal_distribution<double> normal;
  Eigen::VectorXd e(f.mean.size());
  for (int j = 0; j < e.size(); ++j) e(j) = normal(rng);
  return f.mean + Eigen::LLT<Eigen::MatrixXd>(f.cov).matrixL() * e;
}

// Mean over the real samples of the analysis' log-likelihood with the flag known.
double AnalysisScore(const Analysis& r, const Samples& real, bool corrected) {
  if (!corrected) return r.baseline.sim_model.LogLikelihood(real).mean();
  return CorrectedLogLikelihood(r.refinement.problem, r.refinement.selection.fit).mean();
}

TEST(CorrectedModel, FakePairFindsTheSequenceEffect) {
  const Analysis& r = SlipPair().a;
  ASSERT_FALSE(r.correction.terms.empty());
  ASSERT_TRUE(static_cast<bool>(r.correction.shift));
  EXPECT_GT(r.inputs.first_execution_share, 0.0);
  EXPECT_LT(r.inputs.first_execution_share, 1.0);
}

TEST(CorrectedModel, MixturesAreValid) {
  const Pair& p = SlipPair();
  for (const MotionModel& m : {Corrected(p), Sim(p)}) {
    EXPECT_EQ(m.dim(), p.sim.pose_dim() + p.sim.terrain_dim());
    EXPECT_EQ(m.mixtures.size(), p.a.baseline.sim_model.Commands().size());
    for (const auto& [c, mix] : m.mixtures) {
      ASSERT_GT(mix.size(), 1) << "command " << c << ": one Gaussian cannot tile the terrain";
      for (int i = 0; i < mix.size(); ++i) {
        EXPECT_GT(mix.weight(i), 0.0);
        const Eigen::MatrixXd cov = mix.component(i).covariance();
        EXPECT_TRUE(cov.isApprox(cov.transpose()));
        EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(cov).info(), Eigen::Success);
      }
    }
  }
}

// Pointwise: at sim terrain samples and x drawn from the analysis' prediction there, the file's
// conditional log density equals the analysis' flag-mixed density.
double PointwiseError(const Pair& p, bool corrected, const CorrectedModelOptions& options,
                      double* max_error) {
  const MotionModel m = corrected ? Corrected(p, options) : Sim(p, options);
  std::mt19937_64 rng(0);
  std::uniform_int_distribution<int> pick(0, p.sim.size() - 1);
  double sum = 0;
  *max_error = 0;
  const int trials = 200;
  for (int trial = 0; trial < trials; ++trial) {
    const int i = pick(rng);
    const int c = p.sim.command(i);
    const Eigen::VectorXd z = p.sim.z.row(i).transpose();
    const Eigen::VectorXd x = AnalysisDraw(p.a, corrected, c, z, rng);
    const double error = std::abs(m.LogLikelihood(c, x, z) - AnalysisLogDensity(p.a, corrected, c, x, z));
    sum += error;
    *max_error = std::max(*max_error, error);
  }
  return sum / trials;
}

TEST(CorrectedModel, ConditionalMatchesTheAnalysisPrediction) {
  const Pair& p = SlipPair();
  // The pieces are locally linear fits of a smooth prediction (exact means to ~1e-4), but their
  // covariance is the piece's average of the predictive inflation 1 + phi^T A^-1 phi, which
  // varies within a piece: a few hundredths of a nat on average, a few tenths at worst.
  constexpr double kMeanTolerance = 0.05, kMaxTolerance = 0.5;
  for (bool corrected : {true, false}) {
    double max_error = 0;
    const double mean_error = PointwiseError(p, corrected, {}, &max_error);
    EXPECT_LT(mean_error, kMeanTolerance) << (corrected ? "corrected" : "sim");
    EXPECT_LT(max_error, kMaxTolerance) << (corrected ? "corrected" : "sim");
  }
}

// One Gaussian per command (the linear projection the pieces replace) is measurably worse.
TEST(CorrectedModel, PiecesBeatOneGaussianPerCommand) {
  const Pair& p = SlipPair();
  CorrectedModelOptions one;
  one.max_pieces = 1;
  double max_pieces = 0, max_one = 0;
  const double pieces = PointwiseError(p, true, {}, &max_pieces);
  const double single = PointwiseError(p, true, one, &max_one);
  EXPECT_LT(3 * pieces, single);
}

// Mean over the real samples of the analysis' log-likelihood with the flag unknown.
double FlagMixedScore(const Analysis& r, const Samples& real, bool corrected) {
  double sum = 0;
  for (int i = 0; i < real.size(); ++i) {
    sum += AnalysisLogDensity(r, corrected, real.command[i], real.x.row(i).transpose(),
                              real.z.row(i).transpose());
  }
  return sum / real.size();
}

// Whole set: `dgmm score` of the file on the real set equals the analysis' flag-mixed
// log-likelihood, and is at most the entropy of the share below the analysis with the flag known
// (log sum_f s_f N_f >= log s_fi + log N_fi for each sample's own flag f_i).
TEST(CorrectedModel, ScoresTheRealSetLikeTheAnalysis) {
  const Pair& p = SlipPair();
  const double s = p.a.inputs.first_execution_share;
  const double flag_entropy = -s * std::log(s) - (1 - s) * std::log(1 - s);
  // The pieces' averaged inflation (see above), averaged again over the set.
  constexpr double kPieceTolerance = 0.05;
  for (bool corrected : {true, false}) {
    const MotionModel m = corrected ? Corrected(p) : Sim(p);
    const double file = ScoreSampleSet(m, p.real).mean_log_likelihood;
    EXPECT_NEAR(file, FlagMixedScore(p.a, p.real_samples, corrected), kPieceTolerance)
        << (corrected ? "corrected" : "sim");
    EXPECT_GT(file, AnalysisScore(p.a, p.real_samples, corrected) - flag_entropy - kPieceTolerance)
        << (corrected ? "corrected" : "sim");
  }
  EXPECT_GT(ScoreSampleSet(Corrected(p), p.real).mean_log_likelihood, ScoreSampleSet(Sim(p), p.real).mean_log_likelihood);
}

TEST(CorrectedModel, RejectsInvalidOptions) {
  const Pair& p = SlipPair();
  CorrectedModelOptions options;
  options.max_pieces = 0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_FALSE(error.empty());
  EXPECT_ANY_THROW(Corrected(p, options));
}

TEST(CorrectedModel, OnePieceIsOneGaussianPerExecutionKind) {
  const Pair& p = SlipPair();
  CorrectedModelOptions options;
  options.max_pieces = 1;
  const MotionModel m = Corrected(p, options);
  for (const auto& [c, mix] : m.mixtures) EXPECT_EQ(mix.size(), 2);  // first, repeat
}

// Without terrain the file is one Gaussian per execution kind and command, still equal to the
// prediction mixed over the flag: here a hand-made correction (a shift per flag, a noise scale).
TEST(CorrectedModel, WithoutTerrainEachCommandIsItsFlagMixture) {
  SyntheticWorld w;
  w.latency_first_loss = 0.3;
  SampleSet sim = GenerateSynthetic(SyntheticWorld{}, "paper-830", 5);
  SampleSet real_set = GenerateSynthetic(w, "paper", 6);
  for (SampleSet* set : {&sim, &real_set}) {
    set->z.resize(set->size(), 0);
    set->z_names.clear();
    set->z_units.clear();
  }
  const LinearGaussianModel model = LinearGaussianModel::Fit(MakeSamples(sim), {});
  Correction correction;
  correction.log_tau = 0.1;
  correction.shift = [](int c, const Eigen::VectorXd&, double f) {
    Eigen::VectorXd s = Eigen::VectorXd::Constant(6, 0.004 * c);
    s(0) -= 0.05 * f;
    return s;
  };
  const double share = 0.2;
  const MotionModel m = BuildCorrectedModel(model, correction, share, sim);
  EXPECT_EQ(m.terrain_dim, 0);
  const Samples real = MakeSamples(real_set, AlignCommands(sim, real_set));
  const double tau2 = std::exp(2 * correction.log_tau);
  for (int i = 0; i < 10; ++i) {
    const int c = real.command[i];
    ASSERT_EQ(m.MixtureFor(c).size(), 2);
    double log_p[2];
    for (int first = 0; first < 2; ++first) {
      const Prediction pr = model.Predict(c, Eigen::VectorXd(0), first);
      const Eigen::VectorXd mean = pr.mean + correction.Shift(c, Eigen::VectorXd(0), first, 6);
      log_p[first] = std::log(first ? share : 1 - share) +
                     LogNormalDensity(real.x.row(i).transpose(), mean, tau2 * pr.chol * pr.chol.transpose());
    }
    const double top = std::max(log_p[0], log_p[1]);
    const double expected = top + std::log(std::exp(log_p[0] - top) + std::exp(log_p[1] - top));
    EXPECT_NEAR(m.LogLikelihood(c, real.x.row(i).transpose()), expected, 1e-6);
  }
}

}  // namespace
}  // namespace dgmm::sim2real
