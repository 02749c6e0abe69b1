#include "sim2real/sag_mode.h"

#include <algorithm>
#include <cmath>

namespace dgmm::sim2real {
namespace {

// Per sample of s: the deviation from the reference's prediction and its squared Mahalanobis distance.
struct Deviations {
  Eigen::MatrixXd r;  // n x dx
  Eigen::VectorXd m;
};

Deviations Deviate(const SagReference& ref, const Samples& s) {
  return {ref.model.Residuals(s), ref.model.WhitenedResiduals(s).rowwise().squaredNorm()};
}

Gaussian Broad(const SagReference& ref, const SagOptions& options) {
  const double k2 = options.broad_scale * options.broad_scale;
  return Gaussian(Eigen::VectorXd::Zero(ref.spread.rows()), k2 * ref.spread);
}

// One Gaussian of the sags' deviations, floored; the broad one when fewer than d + 2 sags.
Gaussian SagGaussian(const Eigen::MatrixXd& r, const std::vector<int>& sags, const SagReference& ref,
                     const SagOptions& options) {
  const int d = static_cast<int>(r.cols());
  if (static_cast<int>(sags.size()) < d + 2) return Broad(ref, options);
  Eigen::MatrixXd x(sags.size(), d);
  for (size_t j = 0; j < sags.size(); ++j) x.row(j) = r.row(sags[j]);
  const Eigen::VectorXd mean = x.colwise().mean().transpose();
  const Eigen::MatrixXd c = x.rowwise() - mean.transpose();
  Eigen::MatrixXd cov = c.transpose() * c / (x.rows() - 1.0);
  cov.diagonal() += options.floor * ref.spread.diagonal();
  std::optional<Gaussian> g = Gaussian::Create(mean, cov);
  return g ? *g : Broad(ref, options);
}

}  // namespace

SagReference MakeSagReference(const Samples& sim, const LinearGaussianOptions& options) {
  SagReference ref;
  ref.model = LinearGaussianModel::Fit(sim, options);
  const Eigen::MatrixXd r = Deviate(ref, sim).r;
  ref.spread = r.transpose() * r / std::max(1.0, sim.size() - 1.0);
  const double d = sim.pose_dim();
  ref.cut = d + 4 * std::sqrt(2 * d);
  return ref;
}

SagModel FitSagModel(const Samples& s, const std::vector<int>& rows, const SagReference& ref,
                     const LinearGaussianOptions& model, const SagOptions& options) {
  const Deviations dev = Deviate(ref, s);
  std::vector<int> core, sags;
  const int n = rows.empty() ? s.size() : static_cast<int>(rows.size());
  for (int j = 0; j < n; ++j) {
    const int i = rows.empty() ? j : rows[j];
    (dev.m(i) > ref.cut ? sags : core).push_back(i);
  }
  SagModel out;
  out.sags = static_cast<int>(sags.size());
  out.share = (out.sags + 1.0) / (n + 2.0);
  // Too few ordinary samples to fit a core on: the recording is all sags, and its core is all of it.
  out.core = LinearGaussianModel::Fit(s, model, static_cast<int>(core.size()) >= n / 2 ? core : rows);
  out.sag = SagGaussian(dev.r, sags, ref, options);
  return out;
}

Eigen::VectorXd SagLogLikelihood(const SagModel& m, const SagReference& ref, const Samples& s,
                                 const SagOptions& options) {
  const Deviations dev = Deviate(ref, s);
  const Gaussian broad = Broad(ref, options);
  const double e = options.broad_share, p = m.share * (1 - e);
  Eigen::VectorXd out(s.size());
  for (int i = 0; i < s.size(); ++i) {
    const Prediction core = m.core.Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]);
    const double terms[3] = {std::log1p(-e - p) + LogNormal(s.x.row(i).transpose(), core),
                             std::log(p) + m.sag.LogDensity(dev.r.row(i).transpose()),
                             std::log(e) + broad.LogDensity(dev.r.row(i).transpose())};
    const double top = *std::max_element(terms, terms + 3);
    out(i) = top + std::log(std::exp(terms[0] - top) + std::exp(terms[1] - top) + std::exp(terms[2] - top));
  }
  return out;
}

Eigen::VectorXd BroadLogDensity(const SagReference& ref, const Samples& s, const SagOptions& options) {
  const Deviations dev = Deviate(ref, s);
  const Gaussian broad = Broad(ref, options);
  Eigen::VectorXd out(s.size());
  for (int i = 0; i < s.size(); ++i) out(i) = broad.LogDensity(dev.r.row(i).transpose());
  return out;
}

}  // namespace dgmm::sim2real
