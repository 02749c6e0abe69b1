#include "core/motion_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "core_test_utils.h"
#include "util/error.h"

namespace dgmm {
namespace {

using testing::RandomSpd;
using testing::RandomVector;

constexpr double kTol = 1e-10;  // round-off of a few log-sum-exps

// A model with x in 2-D and z in 1-D for commands 0 and 2; command 1 is in the table only.
MotionModel HandMadeModel() {
  std::mt19937_64 rng(0);
  MotionModel model;
  model.pose_dim = 2;
  model.terrain_dim = 1;
  for (int c : {0, 1, 2}) {
    model.command_values[c] = Eigen::VectorXd::Constant(1, c);
    model.command_labels[c] = "c" + std::to_string(c);
  }
  for (int c : {0, 2}) {
    Mixture m(3);
    for (int i = 0; i < 3; ++i) m.Add(1 + i, Gaussian(RandomVector(3, rng), RandomSpd(3, rng)));
    model.mixtures[c] = m;
  }
  return model;
}

// Two commands; x depends on z linearly so terrain is informative.
SampleSet MakeSet(int n, std::mt19937_64& rng) {
  SampleSet set;
  set.command_dim_names = {"speed"};
  set.commands.resize(2, 1);
  set.commands << 0.5, 1.0;
  set.command_labels = {"slow", "fast"};
  set.command.resize(n);
  set.x.resize(n, 2);
  set.z.resize(n, 1);
  set.x_names = {"dx", "dyaw"};
  set.z_names = {"pitch"};
  std::normal_distribution<double> normal;
  for (int i = 0; i < n; ++i) {
    const int c = i % 2;
    set.command[i] = c;
    const double z = normal(rng);
    set.z(i, 0) = z;
    set.x(i, 0) = 10 * (c + 1) + 3 * z + 0.3 * normal(rng);
    set.x(i, 1) = -5 + 0.5 * normal(rng);
  }
  return set;
}

TEST(MotionModelTest, LikelihoodsFollowMarginalAndConditional) {
  const MotionModel model = HandMadeModel();
  std::mt19937_64 rng(1);
  const Eigen::VectorXd x = RandomVector(2, rng), z = RandomVector(1, rng);
  const Mixture& m = model.MixtureFor(2);
  EXPECT_NEAR(model.LogLikelihood(2, x), m.Marginal({0, 1}).LogDensity(x), kTol);
  Eigen::VectorXd y(3);
  y << x, z;
  // Eq. 15: p(x | c, z) = p(x, z | c) / p(z | c).
  EXPECT_NEAR(model.LogLikelihood(2, x, z), m.LogDensity(y) - m.Marginal({2}).LogDensity(z), kTol);
  EXPECT_EQ(model.Conditional(2, z).dim(), 2);
}

// n samples of one command ("velocity") with x = dx and z = (cmd_v, pitch), the command value
// a continuous conditioning dimension; values to be filled by the test.
SampleSet ContinuousCommandSet(int n) {
  SampleSet set;
  set.commands = Eigen::MatrixXd::Zero(1, 0);
  set.command_labels = {"velocity"};
  set.command = Eigen::VectorXi::Zero(n);
  set.x.resize(n, 1);
  set.z.resize(n, 2);
  set.x_names = {"dx"};
  set.z_names = {"cmd_v", "pitch"};
  set.metadata["continuous_command_columns"] = "1";
  return set;
}

// Issue #25: a continuous command is a conditioning dimension like the terrain. A DGMM learnt
// on x (1-D) given z = (command value, pitch), with x bimodal around 2 c + 0.5 pitch, gives
// log p(x | c, pitch) equal to the brute-force conditional log p(x, c, pitch) -
// log integral p(x', c, pitch) dx' (trapezoid rule on a fine grid, which converges exponentially
// for Gaussian integrands) to 1e-9, at command values inside and between the ones seen.
TEST(MotionModelTest, ConditioningOnAContinuousCommandEqualsTheNumericalConditional) {
  std::mt19937_64 rng(25);
  const int n = 600;
  SampleSet set = ContinuousCommandSet(n);
  std::uniform_real_distribution<double> command(-0.5, 0.5);
  std::normal_distribution<double> normal;
  for (int i = 0; i < n; ++i) {
    const double c = command(rng), pitch = 0.1 * normal(rng);
    set.z.row(i) << c, pitch;
    set.x(i, 0) = 2 * c + 0.5 * pitch + (i % 2 ? 0.3 : -0.3) + 0.05 * normal(rng);
  }
  ASSERT_EQ(set.Validate(), "");
  MotionModelOptions options;
  options.dgmm.k = 0.05;  // several components
  const MotionModel model = LearnMotionModel(set, options);
  const Mixture& joint = model.MixtureFor(0);
  ASSERT_GE(joint.size(), 2);
  for (const auto& [c, pitch, x] : std::vector<std::tuple<double, double, double>>{
           {0.25, 0.0, 0.8}, {-0.4, 0.1, -1.1}, {0.013, -0.05, 0.3}, {0.5, 0.2, 0.7}}) {
    const Eigen::Vector2d z(c, pitch);
    const double analytic = model.LogLikelihood(0, Eigen::VectorXd::Constant(1, x), z);
    // The integral of the joint over x' in [-6, 6] (the joint is negligible beyond), step 1e-3.
    auto log_joint = [&](double xp) { return joint.LogDensity(Eigen::Vector3d(xp, c, pitch)); };
    const double peak = log_joint(x);
    double integral = 0;
    const double h = 1e-3;
    for (int k = 0; k <= 12000; ++k) {
      const double w = (k == 0 || k == 12000) ? 0.5 : 1.0;
      integral += w * std::exp(log_joint(-6 + k * h) - peak);
    }
    const double numeric = log_joint(x) - (peak + std::log(integral * h));
    EXPECT_NEAR(analytic, numeric, 1e-9) << "c " << c << " pitch " << pitch << " x " << x;
  }
}

// SamplesNear counts the training samples around a conditioning value: where the model's
// marginal fits the data (Gaussian commands and pitch) it agrees with the kernel-weighted count
// over the training set itself, up to the count's sampling noise; far outside it is near zero.
TEST(MotionModelTest, SamplesNearCountsTrainingDataAroundAConditioningValue) {
  std::mt19937_64 rng(26);
  const int n = 8000;
  SampleSet set = ContinuousCommandSet(n);
  std::normal_distribution<double> normal;
  for (int i = 0; i < n; ++i) {
    set.z.row(i) << 0.2 * normal(rng), 0.1 * normal(rng);
    set.x(i, 0) = 2 * set.z(i, 0) + 0.05 * normal(rng);
  }
  MotionModelOptions options;
  options.dgmm.k = 5;  // one Gaussian, as the data are
  const MotionModel model = LearnMotionModel(set, options);
  const Eigen::Vector2d h(0.1 * 0.2, 0.1 * 0.1);  // 0.1 x the marginal's standard deviations
  for (const Eigen::Vector2d q : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.15, 0.05)}) {
    double count = 0;
    for (int i = 0; i < n; ++i) {
      count += std::exp(-0.5 * (set.z.row(i).transpose() - q).cwiseQuotient(h).squaredNorm());
    }
    EXPECT_GT(count, 25) << q.transpose();
    EXPECT_NEAR(model.SamplesNear(0, q), count, 3 * std::sqrt(count)) << q.transpose();
  }
  EXPECT_LT(model.SamplesNear(0, Eigen::Vector2d(1.5, 0.0)), 1e-3);
  EXPECT_THROW(model.SamplesNear(0, Eigen::VectorXd::Zero(3)), InputError);
}

TEST(MotionModelTest, UnknownOrEmptyCommandIsAClearError) {
  const MotionModel model = HandMadeModel();
  try {
    model.MixtureFor(7);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown command 7"), std::string::npos) << what;
    EXPECT_NE(what.find("model has: 0 ('c0'), 2 ('c2')"), std::string::npos) << what;
  }
  try {
    model.LogLikelihood(1, Eigen::Vector2d(0, 0));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no samples"), std::string::npos) << e.what();
  }
  EXPECT_THROW(model.LogLikelihood(0, Eigen::Vector3d(0, 0, 0)), InputError);
  EXPECT_THROW(model.LogLikelihood(0, Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 0)), InputError);
}

TEST(MotionModelTest, LearnsOneDgmmPerCommandAndIsReproducible) {
  std::mt19937_64 rng(2);
  const SampleSet set = MakeSet(400, rng);
  MotionModelOptions options;
  options.seed = 3;
  const MotionModel a = LearnMotionModel(set, options), b = LearnMotionModel(set, options);
  ASSERT_EQ(a.mixtures.size(), 2u);
  EXPECT_EQ(a.pose_dim, 2);
  EXPECT_EQ(a.terrain_dim, 1);
  EXPECT_EQ(a.command_labels.at(1), "fast");
  EXPECT_EQ(a.seed, 3u);
  for (int c : {0, 1}) {
    EXPECT_EQ(a.mixtures.at(c).total_weight(), 200.0);
    ASSERT_EQ(a.mixtures.at(c).size(), b.mixtures.at(c).size());
    for (int i = 0; i < a.mixtures.at(c).size(); ++i) {
      EXPECT_EQ(a.mixtures.at(c).component(i).mean(), b.mixtures.at(c).component(i).mean());
    }
  }
  options.with_terrain = false;
  const MotionModel no_terrain = LearnMotionModel(set, options);
  EXPECT_EQ(no_terrain.terrain_dim, 0);
  EXPECT_EQ(no_terrain.mixtures.at(0).dim(), 2);
}

TEST(MotionModelTest, ScoreSumsLogLikelihoodsAndTerrainHelps) {
  std::mt19937_64 rng(4);
  const SampleSet train = MakeSet(2000, rng), test = MakeSet(200, rng);
  MotionModelOptions options;
  const MotionModel model = LearnMotionModel(train, options);
  const ScoreSummary s = ScoreSampleSet(model, test);
  EXPECT_EQ(s.samples, 200);
  double total = 0;
  for (int i = 0; i < test.size(); ++i) {
    total +=
        model.LogLikelihood(test.command[i], test.x.row(i).transpose(), test.z.row(i).transpose());
  }
  EXPECT_NEAR(s.total_log_likelihood, total, 1e-8 * std::abs(total));
  EXPECT_NEAR(s.mean_log_likelihood, total / 200, 1e-8 * std::abs(total));
  options.with_terrain = false;
  const ScoreSummary without = ScoreSampleSet(LearnMotionModel(train, options), test);
  // x depends on z with slope 3 and noise 0.3: knowing z must help a lot.
  EXPECT_GT(s.mean_log_likelihood, without.mean_log_likelihood + 0.5);
}

TEST(MotionModelTest, ScoreIsInRawUnitsWhateverTheStandardisation) {
  std::mt19937_64 rng(5);
  const SampleSet raw = MakeSet(300, rng);
  // Standardised copy: y_std = (y - offset) / scale.
  SampleSet standardized = raw;
  standardized.transform.offset = Eigen::Vector3d(10, -5, 0);
  standardized.transform.scale = Eigen::Vector3d(4, 0.5, 2);
  for (int i = 0; i < raw.size(); ++i) {
    const Eigen::VectorXd y =
        (raw.Joint(i) - standardized.transform.offset).cwiseQuotient(standardized.transform.scale);
    standardized.x.row(i) = y.head(2).transpose();
    standardized.z.row(i) = y.tail(1).transpose();
  }
  const MotionModel model = LearnMotionModel(standardized, MotionModelOptions{});
  const ScoreSummary from_std = ScoreSampleSet(model, standardized);
  const ScoreSummary from_raw = ScoreSampleSet(model, raw);
  EXPECT_NEAR(from_std.total_log_likelihood, from_raw.total_log_likelihood,
              1e-9 * std::abs(from_raw.total_log_likelihood));
  // Raw units: the density in std units minus log(4 * 0.5) per sample.
  double std_units = 0;
  for (int i = 0; i < standardized.size(); ++i) {
    std_units += model.LogLikelihood(standardized.command[i], standardized.x.row(i).transpose(),
                                     standardized.z.row(i).transpose());
  }
  EXPECT_NEAR(from_raw.total_log_likelihood, std_units - 300 * std::log(2.0),
              1e-9 * std::abs(std_units));
  SampleSet other = standardized;
  other.transform.scale[0] = 5;
  EXPECT_THROW(ScoreSampleSet(model, other), InputError);
  const MotionModel raw_model = LearnMotionModel(raw, MotionModelOptions{});
  EXPECT_THROW(ScoreSampleSet(raw_model, standardized), InputError);
}

TEST(MotionModelTest, ScoreRejectsMismatchedSets) {
  std::mt19937_64 rng(6);
  const SampleSet set = MakeSet(100, rng);
  const MotionModel model = LearnMotionModel(set, MotionModelOptions{});
  SampleSet wrong = set;
  wrong.x.conservativeResize(Eigen::NoChange, 3);
  wrong.x.col(2).setZero();
  wrong.x_names.push_back("extra");
  EXPECT_THROW(ScoreSampleSet(model, wrong), InputError);
  SampleSet no_terrain = set;
  no_terrain.z.resize(100, 0);
  no_terrain.z_names.clear();
  EXPECT_THROW(ScoreSampleSet(model, no_terrain), InputError);
  SampleSet unknown = set;
  unknown.command_labels = {"slow", "backwards"};
  EXPECT_THROW(ScoreSampleSet(model, unknown), InputError);
  SampleSet nan = set;
  nan.x(3, 1) = std::nan("");
  EXPECT_THROW(ScoreSampleSet(model, nan), InputError);
}

TEST(MotionModelTest, LearnerRejectsBadInput) {
  MotionModel header;
  header.pose_dim = 2;
  MotionModelOptions options;
  options.dgmm.k = 0;
  EXPECT_THROW(MotionModelLearner(header, options), InputError);
  options.dgmm.k = 0.7;
  options.dgmm.initial_covariance_diagonal = Eigen::Vector3d(1, 1, 1);
  EXPECT_THROW(MotionModelLearner(header, options), InputError);
  options.dgmm.initial_covariance_diagonal.resize(0);
  EXPECT_THROW(MotionModelLearner(header, options), InputError);  // data rule, unresolved
  options.dgmm.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;
  MotionModelLearner learner(header, options);
  EXPECT_THROW(learner.Add(0, Eigen::Vector2d(std::nan(""), 0)), InputError);
  EXPECT_THROW(learner.Add(0, Eigen::Vector3d(0, 0, 0)), InputError);
  learner.Add(4, Eigen::Vector2d(1, 1));
  EXPECT_EQ(learner.Finish().mixtures.count(4), 1u);
}

}  // namespace
}  // namespace dgmm
