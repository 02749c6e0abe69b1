#include "sim2real/linear_gaussian.h"

#include <cmath>
#include <numbers>

namespace dgmm::sim2real {
namespace {

// Cholesky of a symmetric matrix with a jitter added until it factors.
Eigen::MatrixXd SafeCholesky(Eigen::MatrixXd s, const Eigen::VectorXd& floor) {
  s = 0.5 * (s + s.transpose());
  s.diagonal() += floor;
  for (int attempt = 0; attempt < 20; ++attempt) {
    Eigen::LLT<Eigen::MatrixXd> llt(s);
    if (llt.info() == Eigen::Success) return llt.matrixL();
    s.diagonal() += floor * std::pow(10.0, attempt + 1);
  }
  return s.diagonal().cwiseMax(1e-12).cwiseSqrt().asDiagonal();
}

}  // namespace

Eigen::VectorXd LinearGaussianModel::Features(const Eigen::Ref<const Eigen::VectorXd>& z,
                                              double first) const {
  const int dz = static_cast<int>(z.size());
  const int quad = quadratic_ ? dz * (dz + 1) / 2 : 0;
  Eigen::VectorXd f(dz + quad + (use_sequence_ ? 1 : 0));
  f.head(dz) = z;
  int k = dz;
  for (int a = 0; a < dz && quadratic_; ++a) {
    for (int b = a; b < dz; ++b) f(k++) = z(a) * z(b);
  }
  if (use_sequence_) f(k) = first;
  return f;
}

Eigen::VectorXd LinearGaussianModel::Phi(const Eigen::Ref<const Eigen::VectorXd>& z, double first) const {
  Eigen::VectorXd f = Features(z, first);
  Eigen::VectorXd phi(f.size() + 1);
  phi << 1.0, f;
  return phi;
}

bool LinearGaussianOptions::IsValid(std::string* error) const {
  if (!(slope_shrinkage >= 0) || !(covariance_pseudo_count >= 0) || !(relative_floor > 0)) {
    if (error) *error = "shrinkage and pseudo-count must be >= 0, the floor > 0";
    return false;
  }
  return true;
}

double LogNormal(const Eigen::Ref<const Eigen::VectorXd>& x, const Prediction& p) {
  Eigen::VectorXd r = p.chol.triangularView<Eigen::Lower>().solve(x - p.mean);
  return -0.5 * (x.size() * std::log(2 * std::numbers::pi) + p.log_det + r.squaredNorm());
}

LinearGaussianModel LinearGaussianModel::Fit(const Samples& s, const LinearGaussianOptions& options,
                                             const std::vector<int>& rows_in) {
  return FitWithPrior(s, options, rows_in, LinearGaussianModel{}, 0.0);
}

// Pooled within-command slopes of x on the covariates: (x - mean_c) regressed on (z - mean_c(z)).
// Also the covariates' scatter per column (the scale of the slopes' ridge).
void LinearGaussianModel::PooledSlopes(const Samples& s, const Eigen::MatrixXd& covariates,
                                       const std::map<int, std::vector<int>>& by_command, Eigen::MatrixXd* slopes,
                                       Eigen::VectorXd* z_scatter) {
  const int dz = static_cast<int>(covariates.cols()), dx = s.pose_dim();
  Eigen::MatrixXd zz = Eigen::MatrixXd::Zero(dz, dz), zx = Eigen::MatrixXd::Zero(dz, dx);
  *z_scatter = Eigen::VectorXd::Zero(dz);
  for (const auto& [c, idx] : by_command) {
    Eigen::VectorXd xm = Eigen::VectorXd::Zero(dx), zm = Eigen::VectorXd::Zero(dz);
    for (int i : idx) {
      xm += s.x.row(i).transpose();
      if (dz) zm += covariates.row(i).transpose();
    }
    xm /= idx.size();
    zm /= idx.size();
    for (int i : idx) {
      if (!dz) break;
      Eigen::VectorXd zc = covariates.row(i).transpose() - zm;
      zz += zc * zc.transpose();
      zx += zc * (s.x.row(i).transpose() - xm).transpose();
      *z_scatter += zc.cwiseAbs2();
    }
  }
  *slopes = Eigen::MatrixXd::Zero(dz, dx);
  if (dz) {
    Eigen::MatrixXd reg = zz;
    reg.diagonal() += 1e-9 * (1.0 + zz.diagonal().array()).matrix();
    *slopes = reg.ldlt().solve(zx);
  }
}

// One command's ridge fit of W (slopes towards `prior_w`'s, all towards the prior model's with
// weight prior_count when it has the command), its terrain moments and residual scatter *sc.
LinearGaussianModel::PerCommand LinearGaussianModel::FitCommand(
    const Samples& s, const std::vector<int>& idx, const Eigen::MatrixXd& covariates, const PerCommand* from_prior,
    double prior_count, const Eigen::MatrixXd& pooled_slopes, const Eigen::VectorXd& z_scatter, double n_rows,
    const LinearGaussianOptions& options, Eigen::MatrixXd* sc) const {
  const int dz = static_cast<int>(covariates.cols()), dx = pose_dim_, p = dz + 1;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, p), b = Eigen::MatrixXd::Zero(p, dx);
  auto phi_of = [&](int i) { return Phi(s.z.row(i).transpose(), use_sequence_ ? s.first_execution[i] : 0.0); };
  for (int i : idx) {
    const Eigen::VectorXd phi = phi_of(i);
    a += phi * phi.transpose();
    b += phi * s.x.row(i);
  }
  PerCommand pc;
  pc.gram = a;
  pc.count = idx.size();
  Eigen::MatrixXd prior_w = Eigen::MatrixXd::Zero(p, dx);
  prior_w.bottomRows(dz) = pooled_slopes;
  if (from_prior) {
    const Eigen::MatrixXd lambda = prior_count * from_prior->gram / std::max(1.0, from_prior->count);
    a += lambda;
    b += lambda * from_prior->w;
    prior_w = from_prior->w;
  }
  for (int j = 0; j < dz; ++j) {
    // Penalty relative to the pooled scatter of z per sample, times the command's count.
    const double lambda = options.slope_shrinkage * z_scatter(j) / n_rows * idx.size() + 1e-12;
    a(j + 1, j + 1) += lambda;
    b.row(j + 1) += lambda * prior_w.row(j + 1);
  }
  a(0, 0) += 1e-12;
  pc.w = a.ldlt().solve(b);
  pc.a_inv = a.ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  *sc = Eigen::MatrixXd::Zero(dx, dx);
  pc.z_mean = Eigen::VectorXd::Zero(dz);
  pc.z_cov = Eigen::MatrixXd::Zero(dz, dz);
  for (int i : idx) {
    const Eigen::VectorXd r = s.x.row(i).transpose() - pc.w.transpose() * phi_of(i);
    *sc += r * r.transpose();
    if (dz) pc.z_mean += covariates.row(i).transpose();
  }
  if (dz) {
    pc.z_mean /= idx.size();
    for (int i : idx) {
      const Eigen::VectorXd zc = covariates.row(i).transpose() - pc.z_mean;
      pc.z_cov += zc * zc.transpose();
    }
    pc.z_cov /= std::max<double>(1.0, idx.size() - 1.0);
  }
  return pc;
}

LinearGaussianModel LinearGaussianModel::FitWithPrior(const Samples& s,
                                                      const LinearGaussianOptions& options,
                                                      const std::vector<int>& rows_in,
                                                      const LinearGaussianModel& prior,
                                                      double prior_count) {
  std::vector<int> rows = rows_in;
  if (rows.empty()) {
    for (int i = 0; i < s.size(); ++i) rows.push_back(i);
  }
  LinearGaussianModel m;
  m.pose_dim_ = s.pose_dim();
  m.terrain_dim_ = s.terrain_dim();
  m.use_sequence_ = options.use_sequence && s.has_sequence;
  if (prior_count > 0 && !prior.commands_.empty()) m.use_sequence_ = prior.use_sequence_;
  m.quadratic_ = options.quadratic_terrain && m.terrain_dim_ > 0;
  if (prior_count > 0 && !prior.commands_.empty()) m.quadratic_ = prior.quadratic_;
  // Covariates after the intercept: z, its products (if quadratic), the first-execution flag.
  const int dz = static_cast<int>(m.Features(Eigen::VectorXd::Zero(m.terrain_dim_), 0.0).size());
  Eigen::MatrixXd covariates(s.size(), dz);
  for (int i = 0; i < s.size(); ++i) {
    covariates.row(i) = m.Features(s.z.row(i).transpose(), s.first_execution[i]).transpose();
  }
  const int dx = m.pose_dim_, p = dz + 1;
  std::map<int, std::vector<int>> by_command;
  for (int i : rows) by_command[s.command[i]].push_back(i);
  Eigen::MatrixXd pooled_slopes;
  Eigen::VectorXd z_scatter;
  PooledSlopes(s, covariates, by_command, &pooled_slopes, &z_scatter);
  const double n_rows = std::max<double>(1.0, rows.size());
  Eigen::MatrixXd pooled_scatter = Eigen::MatrixXd::Zero(dx, dx);
  std::map<int, Eigen::MatrixXd> scatter;
  for (const auto& [c, idx] : by_command) {
    auto it = prior.commands_.find(c);
    const PerCommand* from_prior = prior_count > 0 && it != prior.commands_.end() ? &it->second : nullptr;
    m.commands_[c] = m.FitCommand(s, idx, covariates, from_prior, prior_count, pooled_slopes, z_scatter, n_rows,
                                  options, &scatter[c]);
    pooled_scatter += scatter[c];
  }
  // Residual degrees of freedom: n - p per command.
  const double dof = std::max(1.0, n_rows - static_cast<double>(p * by_command.size()));
  m.SetCovariances(pooled_scatter / dof, scatter, by_command, prior, prior_count, options, p);
  m.pooled_.w.bottomRows(dz) = pooled_slopes;
  return m;
}

// Each command's covariance: its residual scatter shrunk towards the pooled covariance (and the
// prior's), floored; the fallback for commands without data (intercept 0, pooled covariance).
void LinearGaussianModel::SetCovariances(const Eigen::MatrixXd& pooled_cov, const std::map<int, Eigen::MatrixXd>& scatter,
                                         const std::map<int, std::vector<int>>& by_command,
                                         const LinearGaussianModel& prior, double prior_count,
                                         const LinearGaussianOptions& options, int p) {
  const int dx = pose_dim_, dz = p - 1;
  const Eigen::VectorXd floor = options.relative_floor * pooled_cov.diagonal().cwiseMax(1e-12);
  const double nu = options.covariance_pseudo_count;
  Eigen::MatrixXd all_z_cov = Eigen::MatrixXd::Zero(dz, dz);
  for (auto& [c, pc] : commands_) {
    const double n_c = by_command.at(c).size();
    Eigen::MatrixXd cov = (scatter.at(c) + nu * pooled_cov) / std::max(1e-9, n_c - p + nu);
    auto from_prior = prior.commands_.find(c);
    if (prior_count > 0 && from_prior != prior.commands_.end()) {
      const Eigen::MatrixXd& l = from_prior->second.chol;
      cov = (scatter.at(c) + nu * pooled_cov + prior_count * l * l.transpose()) /
            std::max(1e-9, n_c - p + nu + prior_count);
    }
    pc.chol = SafeCholesky(cov, floor);
    pc.log_det = 2 * pc.chol.diagonal().array().log().sum();
    pc.z_cov += 1e-8 * Eigen::MatrixXd::Identity(dz, dz);
    all_z_cov += pc.z_cov;
  }
  pooled_.w = Eigen::MatrixXd::Zero(p, dx);
  pooled_.a_inv = Eigen::MatrixXd::Zero(p, p);
  pooled_.chol = SafeCholesky(pooled_cov, floor);
  pooled_.log_det = 2 * pooled_.chol.diagonal().array().log().sum();
  pooled_.z_mean = Eigen::VectorXd::Zero(dz);
  pooled_.z_cov = all_z_cov / std::max<size_t>(1, commands_.size());
}

Prediction LinearGaussianModel::Predict(int command, const Eigen::Ref<const Eigen::VectorXd>& z,
                                        double first) const {
  auto it = commands_.find(command);
  const PerCommand& pc = it == commands_.end() ? pooled_ : it->second;
  Prediction p;
  const Eigen::VectorXd phi = Phi(z, first);
  p.mean = pc.w.transpose() * phi;
  const double inflation = 1.0 + std::max(0.0, phi.dot(pc.a_inv * phi));
  p.chol = pc.chol * std::sqrt(inflation);
  p.log_det = pc.log_det + pose_dim_ * std::log(inflation);
  return p;
}

Eigen::VectorXd LinearGaussianModel::LogLikelihood(const Samples& s) const {
  Eigen::VectorXd ll(s.size());
  for (int i = 0; i < s.size(); ++i) {
    ll(i) = LogNormal(s.x.row(i).transpose(), Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]));
  }
  return ll;
}

Eigen::MatrixXd LinearGaussianModel::Residuals(const Samples& s) const {
  Eigen::MatrixXd r(s.size(), s.pose_dim());
  for (int i = 0; i < s.size(); ++i) {
    r.row(i) = s.x.row(i) - Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]).mean.transpose();
  }
  return r;
}

Eigen::MatrixXd LinearGaussianModel::WhitenedResiduals(const Samples& s) const {
  Eigen::MatrixXd r(s.size(), s.pose_dim());
  for (int i = 0; i < s.size(); ++i) {
    Prediction p = Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]);
    r.row(i) = p.chol.triangularView<Eigen::Lower>().solve(s.x.row(i).transpose() - p.mean).transpose();
  }
  return r;
}

Eigen::VectorXd LinearGaussianModel::TerrainMean(int c) const {
  auto it = commands_.find(c);
  return (it == commands_.end() ? pooled_.z_mean : it->second.z_mean).head(terrain_dim_);
}

Eigen::MatrixXd LinearGaussianModel::TerrainCovariance(int c) const {
  auto it = commands_.find(c);
  return (it == commands_.end() ? pooled_.z_cov : it->second.z_cov).topLeftCorner(terrain_dim_, terrain_dim_);
}

std::vector<int> LinearGaussianModel::Commands() const {
  std::vector<int> out;
  for (const auto& [c, pc] : commands_) out.push_back(c);
  return out;
}

}  // namespace dgmm::sim2real
