#include "predict/step_persistence.h"

#include <cmath>
#include <limits>
#include <map>

#include "predict/episode_set.h"
#include "util/error.h"

namespace dgmm::predict {

bool StepPersistence::IsValid(std::string* error) const {
  auto in_unit = [](const Eigen::VectorXd& v) { return ((v.array() >= 0) && (v.array() <= 1)).all(); };
  if (shared.size() != decay.size() || !in_unit(shared) || !in_unit(decay)) {
    if (error) *error = "persistence: expected a shared share and a decay in [0, 1] per pose dimension";
    return false;
  }
  if (first_scale.size() > 0 &&
      (first_scale.size() != shared.size() || !((first_scale.array() > 0) && (first_scale.array() <= 10)).all())) {
    if (error) *error = "persistence: expected a first-step scale in (0, 10] per pose dimension";
    return false;
  }
  return true;
}

namespace {

// eps_i = L_k^-1 (x_i - mu_k) under the most responsible component k of p(x | c_i, z_i): pose_dim x n.
Eigen::MatrixXd StandardisedResiduals(const MotionModel& model, const SampleSet& set, const std::string& source) {
  Eigen::MatrixXd eps(model.pose_dim, set.size());
  for (int i = 0; i < set.size(); ++i) {
    const int id = ModelCommandId(model, set, set.command[i], source);
    if (!model.HasCommand(id)) throw MakeInputError(source, "command", "command " + std::to_string(id) + " is not in the model");
    const Eigen::VectorXd z = model.terrain_dim > 0 ? Eigen::VectorXd(set.z.row(i).transpose()) : Eigen::VectorXd();
    const Mixture p = model.RawPoseDistribution(id, z);
    const Eigen::VectorXd x = set.x.row(i).transpose();
    Eigen::Index k = 0;
    p.LogResponsibilities(x).maxCoeff(&k);
    const Gaussian& g = p.component(static_cast<int>(k));
    eps.col(i) = g.cholesky_l().triangularView<Eigen::Lower>().solve(x - g.mean());
  }
  return eps;
}

// Pearson correlation of eps rows between the samples of `a` and those of `b`, per dimension.
Eigen::VectorXd Correlation(const Eigen::MatrixXd& eps, const std::vector<int>& a, const std::vector<int>& b) {
  Eigen::VectorXd out(eps.rows());
  for (Eigen::Index d = 0; d < eps.rows(); ++d) {
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    for (std::size_t j = 0; j < a.size(); ++j) {
      const double u = eps(d, a[j]), v = eps(d, b[j]);
      sa += u, sb += v, saa += u * u, sbb += v * v, sab += u * v;
    }
    const double n = static_cast<double>(a.size());
    const double cov = sab - sa * sb / n, va = saa - sa * sa / n, vb = sbb - sb * sb / n;
    out[d] = va > 0 && vb > 0 ? cov / std::sqrt(va * vb) : 0.0;
  }
  return out;
}

// (a, phi) minimising sum_l (rho_l - a phi^l)^2 over the finite rho_l.
std::pair<double, double> FitDecay(const Eigen::VectorXd& rho) {
  double best_error = std::numeric_limits<double>::infinity(), best_a = 0, best_phi = 0;
  for (int g = 0; g <= 99; ++g) {
    const double phi = 0.01 * g;
    double pr = 0, pp = 0;
    for (Eigen::Index l = 0; l < rho.size(); ++l) {
      if (!std::isfinite(rho[l])) continue;
      const double p = std::pow(phi, static_cast<double>(l + 1));
      pr += p * rho[l], pp += p * p;
    }
    const double a = pp > 0 ? std::clamp(pr / pp, 0.0, 1.0) : 0.0;
    double error = 0;
    for (Eigen::Index l = 0; l < rho.size(); ++l) {
      if (std::isfinite(rho[l])) error += std::pow(rho[l] - a * std::pow(phi, static_cast<double>(l + 1)), 2);
    }
    if (error < best_error - 1e-15) best_error = error, best_a = a, best_phi = phi;
  }
  return {best_a, best_phi};
}

}  // namespace

PersistenceSummary EstimatePersistence(const MotionModel& model, const SampleSet& set, const PersistenceOptions& options,
                                       const std::string& source) {
  CheckEpisodeSet(model, set, source, "persistence");
  if (options.max_lag < 1 || options.min_pairs < 2) throw MakeInputError("persistence", "options", "expected max_lag >= 1, min_pairs >= 2");
  const Eigen::MatrixXd eps = StandardisedResiduals(model, set, source);
  std::map<std::pair<int, int>, int> row;  // (episode, step) -> sample
  std::map<int, int> steps_in;
  for (int i = 0; i < set.size(); ++i) row[{set.episode[i], set.step[i]}] = i, ++steps_in[set.episode[i]];
  PersistenceSummary out;
  for (const auto& [e, n] : steps_in) out.episodes += n >= 2;
  out.lag_correlation = Eigen::MatrixXd::Constant(model.pose_dim, options.max_lag, NAN);
  out.pairs = Eigen::VectorXi::Zero(options.max_lag);
  for (int l = 1; l <= options.max_lag; ++l) {
    std::vector<int> a, b;
    for (const auto& [key, i] : row) {
      const auto later = row.find({key.first, key.second + l});
      if (later != row.end()) a.push_back(i), b.push_back(later->second);
    }
    out.pairs[l - 1] = static_cast<int>(a.size());
    if (static_cast<int>(a.size()) >= options.min_pairs) out.lag_correlation.col(l - 1) = Correlation(eps, a, b);
  }
  if (out.pairs[0] < options.min_pairs) {
    throw MakeInputError(source, "episode", "expected at least " + std::to_string(options.min_pairs) +
                                                      " pairs of consecutive steps, found " + std::to_string(out.pairs[0]));
  }
  out.residual_rms = (eps.cwiseAbs2().rowwise().sum() / set.size()).cwiseSqrt();
  out.persistence.first_scale = Eigen::VectorXd::Ones(model.pose_dim);
  Eigen::VectorXd square_sum = Eigen::VectorXd::Zero(model.pose_dim);
  for (int i = 0; i < set.size(); ++i) {
    if (set.step[i] == 0) square_sum += eps.col(i).cwiseAbs2(), ++out.first_steps;
  }
  if (out.first_steps >= options.min_pairs) {
    out.persistence.first_scale = (square_sum / out.first_steps).cwiseSqrt().cwiseMax(0.1).cwiseMin(10.0);
  }
  out.persistence.shared.resize(model.pose_dim);
  out.persistence.decay.resize(model.pose_dim);
  for (int d = 0; d < model.pose_dim; ++d) {
    const auto [a, phi] = FitDecay(out.lag_correlation.row(d).transpose());
    out.persistence.shared[d] = a;
    out.persistence.decay[d] = phi;
  }
  return out;
}

}  // namespace dgmm::predict
