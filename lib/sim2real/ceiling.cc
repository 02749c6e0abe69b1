#include "sim2real/ceiling.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "sim2real/selection.h"

namespace dgmm::sim2real {
namespace {

// Held-out log-likelihood of each real sample under a real-trained model (folds `fold`), with the
// sim model as a prior of strength `prior_count` (0: real data only).
Eigen::VectorXd RealTrainedHeldout(const Samples& real, const LinearGaussianOptions& options,
                                   const std::vector<int>& fold, const LinearGaussianModel& sim_model,
                                   double prior_count) {
  std::vector<int> rows(real.size());
  for (int i = 0; i < real.size(); ++i) rows[i] = i;
  Eigen::VectorXd ll(real.size());
  const int folds = *std::max_element(fold.begin(), fold.end()) + 1;
  for (int f = 0; f < folds; ++f) {
    const FoldSplit split = SplitFold(rows, fold, f);
    if (split.test.empty()) continue;
    const LinearGaussianModel m = LinearGaussianModel::FitWithPrior(real, options, split.train, sim_model, prior_count);
    const Eigen::VectorXd t = m.LogLikelihood(SubsetSamples(real, split.test));
    for (size_t k = 0; k < split.test.size(); ++k) ll(split.test[k]) = t(k);
  }
  return ll;
}

// Samples with the commands, terrain and sequence of `design`, x drawn from `truth`: whitened
// noise sqrt(1 - rho) e + sqrt(rho) u, u shared by the executions of a placement.
Samples DrawFrom(const LinearGaussianModel& truth, const Samples& design, const Eigen::VectorXd& rho,
                 std::mt19937_64& rng) {
  Samples s = design;
  const int dx = design.pose_dim();
  std::normal_distribution<double> normal;
  auto standard = [&] {
    Eigen::VectorXd v(dx);
    for (int d = 0; d < dx; ++d) v(d) = normal(rng);
    return v;
  };
  const bool shares = rho.size() == dx;  // without a share no placement draw (the same stream as before)
  const Eigen::ArrayXd shared = shares ? rho.array().sqrt().eval() : Eigen::ArrayXd::Zero(dx);
  const Eigen::ArrayXd own = (1.0 - shared.square()).sqrt();
  std::map<int, Eigen::VectorXd> placement;
  for (int i = 0; i < s.size(); ++i) {
    Eigen::VectorXd w = standard();
    if (shares) {
      auto it = placement.find(s.episode[i]);
      if (it == placement.end()) it = placement.emplace(s.episode[i], standard()).first;
      w = (own * w.array() + shared * it->second.array()).matrix();
    }
    const Prediction p = truth.Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]);
    s.x.row(i) = (p.mean + p.chol * w).transpose();
  }
  return s;
}

}  // namespace

CeilingFit FitCeiling(const Samples& real, const LinearGaussianOptions& options, const std::vector<int>& fold,
                      const LinearGaussianModel& sim_model) {
  CeilingFit c;
  for (double prior_count : {0.0, 3.0, 10.0, 30.0, 100.0}) {
    const Eigen::VectorXd ll = RealTrainedHeldout(real, options, fold, sim_model, prior_count);
    if (prior_count == 0) c.ll_real_only = ll.mean();
    if (c.heldout.size() == 0 || ll.mean() > c.heldout.mean()) {
      c.heldout = ll;
      c.prior_count = prior_count;
    }
  }
  return c;
}

bool NullShortfallOptions::IsValid(std::string* error) const {
  if (draws < 0) {
    if (error) *error = "null shortfall: draws >= 0";
    return false;
  }
  return true;
}

NullShortfall SimNullShortfall(const LinearGaussianModel& sim_model, const Samples& sim, const Samples& real,
                               const std::vector<int>& fold, const LinearGaussianOptions& model,
                               const NullShortfallOptions& options) {
  std::mt19937_64 rng(options.seed);
  std::vector<double> s;
  for (int d = 0; d < options.draws; ++d) {
    const Samples sim_d = DrawFrom(sim_model, sim, options.placement_correlation, rng);
    const Samples real_d = DrawFrom(sim_model, real, options.placement_correlation, rng);
    const LinearGaussianModel m = LinearGaussianModel::Fit(sim_d, model);
    s.push_back(FitCeiling(real_d, model, fold, m).heldout.mean() - m.LogLikelihood(real_d).mean());
  }
  NullShortfall out;
  out.draws = static_cast<int>(s.size());
  if (s.empty()) return out;
  double sum = 0, sum2 = 0;
  for (double v : s) sum += v, sum2 += v * v;
  out.mean = sum / s.size();
  out.sd = s.size() > 1 ? std::sqrt(std::max(0.0, (sum2 - s.size() * out.mean * out.mean) / (s.size() - 1))) : 0.0;
  return out;
}

}  // namespace dgmm::sim2real
