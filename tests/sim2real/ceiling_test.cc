// The ceiling's null: where real and sim physics agree, the real-trained ceiling still beats the
// sim model by the sim model's own estimation error. The null shortfall, drawn from the fitted sim
// model, predicts that gap for independent real sets of the same physics, and the shortfall of
// physics the sim lacks stands above it.
#include "sim2real/ceiling.h"

#include <gtest/gtest.h>

#include "sim2real/selection.h"
#include "tests/sim2real/synthetic.h"

namespace dgmm::sim2real {
namespace {

Samples Make(const SyntheticWorld& w, const std::string& protocol, std::uint64_t seed) {
  return MakeSamples(GenerateSynthetic(w, protocol, seed));
}

std::vector<int> Folds(const Samples& real, std::uint64_t seed) {
  std::vector<int> rows(real.size());
  for (int i = 0; i < real.size(); ++i) rows[i] = i;
  std::mt19937_64 rng(seed);
  return MakeFolds(real.episode, real.command, rows, 5, rng);
}

// ceiling - sim model on `real` (the baseline's arithmetic).
double Shortfall(const LinearGaussianModel& m, const Samples& real, const std::vector<int>& fold) {
  return FitCeiling(real, LinearGaussianOptions{}, fold, m).heldout.mean() - m.LogLikelihood(real).mean();
}

NullShortfall Null(const Samples& sim, const Samples& real, const std::vector<int>& fold, int draws = 20) {
  const LinearGaussianModel m = LinearGaussianModel::Fit(sim, LinearGaussianOptions{});
  NullShortfallOptions o;
  o.draws = draws;
  return SimNullShortfall(m, sim, real, fold, LinearGaussianOptions{}, o);
}

TEST(NullShortfall, PredictsTheShortfallOfRealSetsWithTheSimsPhysics) {
  // Independent sim sets and real sets of one physics: the measured shortfall's mean and spread
  // against the null each sim set predicts from itself and the real set's design.
  const int pairs = 12;
  std::vector<double> measured, predicted;
  for (int k = 0; k < pairs; ++k) {
    const Samples sim = Make(SyntheticWorld{}, "paper-830", 200 + k), real = Make(SyntheticWorld{}, "paper", 300 + k);
    const std::vector<int> fold = Folds(real, k);
    measured.push_back(Shortfall(LinearGaussianModel::Fit(sim, LinearGaussianOptions{}), real, fold));
    predicted.push_back(Null(sim, real, fold).mean);
  }
  const Eigen::Map<Eigen::VectorXd> m(measured.data(), pairs), p(predicted.data(), pairs);
  const double sd = std::sqrt((m.array() - m.mean()).square().sum() / (pairs - 1));
  // The sim model's estimation error is real: the ceiling beats it on same-physics real sets ...
  EXPECT_GT(m.mean(), 3 * sd / std::sqrt(pairs));
  // ... and the null predicts by how much, within the measured mean's sampling error.
  EXPECT_NEAR(p.mean(), m.mean(), 3 * sd / std::sqrt(pairs)) << "predicted " << p.mean() << " measured " << m.mean();
}

TEST(NullShortfall, MissingPhysicsStandsAboveTheNull) {
  const Samples sim = Make(SyntheticWorld{}, "paper-830", 22);
  SyntheticWorld slipping;
  slipping.slip_creep = 0.05;
  const Samples real = Make(slipping, "paper", 7);
  const std::vector<int> fold = Folds(real, 7);
  const NullShortfall null = Null(sim, real, fold);
  const double shortfall = Shortfall(LinearGaussianModel::Fit(sim, LinearGaussianOptions{}), real, fold);
  EXPECT_GT(shortfall - null.mean, 3 * null.sd + 0.05) << "null " << null.mean << " shortfall " << shortfall;
}

TEST(NullShortfall, PlacementsSharingTheirNoiseRaiseTheNull) {
  // Executions of a placement that share half their noise carry less information than as many
  // independent ones: the sim model's estimation error, and so the null, grow.
  const Samples sim = Make(SyntheticWorld{}, "paper-830", 25), real = Make(SyntheticWorld{}, "paper", 25);
  const std::vector<int> fold = Folds(real, 1);
  const LinearGaussianModel m = LinearGaussianModel::Fit(sim, LinearGaussianOptions{});
  NullShortfallOptions o;
  const NullShortfall independent = SimNullShortfall(m, sim, real, fold, LinearGaussianOptions{}, o);
  o.placement_correlation = Eigen::VectorXd::Constant(6, 0.5);
  const NullShortfall shared = SimNullShortfall(m, sim, real, fold, LinearGaussianOptions{}, o);
  EXPECT_GT(shared.mean, independent.mean + 2 * independent.sd / std::sqrt(20.0))
      << "shared " << shared.mean << " independent " << independent.mean;
}

TEST(NullShortfall, NoDrawsNoNull) {
  const Samples sim = Make(SyntheticWorld{}, "paper-830", 23), real = Make(SyntheticWorld{}, "paper", 23);
  const NullShortfall null = Null(sim, real, Folds(real, 1), 0);
  EXPECT_EQ(null.draws, 0);
  EXPECT_EQ(null.mean, 0.0);
}

TEST(NullShortfall, SameSeedSameNull) {
  const Samples sim = Make(SyntheticWorld{}, "paper-830", 24), real = Make(SyntheticWorld{}, "paper", 24);
  const std::vector<int> fold = Folds(real, 1);
  const NullShortfall a = Null(sim, real, fold), b = Null(sim, real, fold);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.sd, b.sd);
  EXPECT_EQ(a.draws, 20);
}

}  // namespace
}  // namespace dgmm::sim2real
