#include "core/gaussian.h"

#include <cassert>
#include <cmath>
#include <numbers>

namespace dgmm {
namespace {

// log(2 pi).
constexpr double kLog2Pi = 1.8378770664093454835606594728112;

// Lower Cholesky factor of the symmetric matrix `covariance` into *l; false if not PD or
// not finite. Only the lower triangle of `covariance` is read.
bool Factor(const Eigen::MatrixXd& covariance, Eigen::MatrixXd* l) {
  if (covariance.rows() != covariance.cols() || !covariance.allFinite()) return false;
  *l = covariance;
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(*l);  // in place: *l holds the factor
  if (llt.info() != Eigen::Success) return false;
  for (int i = 0; i < l->rows(); ++i) {
    if (!((*l)(i, i) > 0.0) || !std::isfinite((*l)(i, i))) return false;
  }
  l->triangularView<Eigen::StrictlyUpper>().setZero();
  return true;
}

// Symmetric part (S + S^T) / 2, removing round-off asymmetry of products such as A S A^T.
Eigen::MatrixXd Symmetrize(const Eigen::MatrixXd& s) { return 0.5 * (s + s.transpose()); }

// A Gaussian from a covariance that is PD in exact arithmetic (Schur complement, A S A^T of a
// full-rank A) but may lose definiteness to round-off: retried with a relative jitter.
Gaussian MakeWithJitter(Eigen::VectorXd mean, Eigen::MatrixXd covariance) {
  covariance = Symmetrize(covariance);
  if (auto g = Gaussian::Create(mean, covariance)) return *std::move(g);
  const int d = static_cast<int>(covariance.rows());
  double scale = d > 0 ? std::abs(covariance.trace()) / d : 1.0;
  if (!(scale > 0) || !std::isfinite(scale)) scale = 1.0;
  for (double jitter = 1e-12 * scale; jitter <= 1e-3 * scale; jitter *= 10) {
    Eigen::MatrixXd c = covariance;
    c.diagonal().array() += jitter;
    if (auto g = Gaussian::Create(mean, c)) return *std::move(g);
  }
  assert(false && "covariance is not positive definite");
  return Gaussian(std::move(mean), Eigen::MatrixXd::Identity(d, d) * scale);
}

}  // namespace

Gaussian::Gaussian(Eigen::VectorXd mean, Eigen::MatrixXd covariance) {
  [[maybe_unused]] const bool ok = Set(std::move(mean), std::move(covariance));
  assert(ok && "Gaussian: covariance must be symmetric positive definite");
}

std::optional<Gaussian> Gaussian::Create(Eigen::VectorXd mean, Eigen::MatrixXd covariance) {
  Gaussian g;
  if (!g.Set(std::move(mean), std::move(covariance))) return std::nullopt;
  return g;
}

bool Gaussian::Set(Eigen::VectorXd mean, Eigen::MatrixXd covariance) {
  if (covariance.rows() != mean.size() || !mean.allFinite()) return false;
  Eigen::MatrixXd l;
  if (!Factor(covariance, &l)) return false;
  mean_ = std::move(mean);
  covariance_ = std::move(covariance);
  l_ = std::move(l);
  log_det_ = 2.0 * l_.diagonal().array().log().sum();
  return true;
}

bool Gaussian::SetInPlace(const Eigen::Ref<const Eigen::VectorXd>& mean,
                          const Eigen::Ref<const Eigen::MatrixXd>& covariance) {
  const int d = static_cast<int>(mean.size());
  if (covariance.rows() != d || covariance.cols() != d || !covariance.allFinite() ||
      !mean.allFinite()) {
    return false;
  }
  scratch_ = covariance;
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(scratch_);
  if (llt.info() != Eigen::Success) return false;
  for (int i = 0; i < d; ++i) {
    if (!(scratch_(i, i) > 0.0) || !std::isfinite(scratch_(i, i))) return false;
  }
  scratch_.triangularView<Eigen::StrictlyUpper>().setZero();
  l_.swap(scratch_);
  mean_ = mean;
  covariance_ = covariance;
  log_det_ = 2.0 * l_.diagonal().array().log().sum();
  return true;
}

double Gaussian::SquaredMahalanobis(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  assert(x.size() == mean_.size());
  const int d = dim();
  // Forward substitution L u = x - mean without a heap allocation for small d.
  constexpr int kStack = 32;
  if (d <= kStack) {
    double u[kStack];
    double m2 = 0.0;
    for (int i = 0; i < d; ++i) {
      double s = x[i] - mean_[i];
      for (int j = 0; j < i; ++j) s -= l_(i, j) * u[j];
      u[i] = s / l_(i, i);
      m2 += u[i] * u[i];
    }
    return m2;
  }
  Eigen::VectorXd u = x - mean_;
  l_.triangularView<Eigen::Lower>().solveInPlace(u);
  return u.squaredNorm();
}

double Gaussian::LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  return -0.5 * (dim() * kLog2Pi + log_det_ + SquaredMahalanobis(x));
}

Eigen::VectorXd Gaussian::LogDensity(const Eigen::Ref<const Eigen::MatrixXd>& X) const {
  assert(X.rows() == mean_.size());
  Eigen::MatrixXd u = X.colwise() - mean_;
  l_.triangularView<Eigen::Lower>().solveInPlace(u);
  const double c = dim() * kLog2Pi + log_det_;
  return (-0.5 * (u.colwise().squaredNorm().array() + c)).transpose();
}

double Gaussian::ScaledDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  return std::exp(-0.5 * SquaredMahalanobis(x));
}

Gaussian Gaussian::Marginal(const std::vector<int>& dims) const {
  const int k = static_cast<int>(dims.size());
  Eigen::VectorXd m(k);
  Eigen::MatrixXd s(k, k);
  for (int i = 0; i < k; ++i) {
    assert(dims[i] >= 0 && dims[i] < dim());
    m[i] = mean_[dims[i]];
    for (int j = 0; j < k; ++j) s(i, j) = covariance_(dims[i], dims[j]);
  }
  return MakeWithJitter(std::move(m), std::move(s));
}

Gaussian Gaussian::Conditional(const std::vector<int>& given_dims,
                               const Eigen::Ref<const Eigen::VectorXd>& values) const {
  assert(static_cast<int>(given_dims.size()) == values.size());
  const std::vector<int> a = ComplementDims(dim(), given_dims);
  const std::vector<int>& b = given_dims;
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  Eigen::VectorXd mean_a(na), mean_b(nb);
  Eigen::MatrixXd s_aa(na, na), s_ab(na, nb), s_bb(nb, nb);
  for (int i = 0; i < na; ++i) {
    mean_a[i] = mean_[a[i]];
    for (int j = 0; j < na; ++j) s_aa(i, j) = covariance_(a[i], a[j]);
    for (int j = 0; j < nb; ++j) s_ab(i, j) = covariance_(a[i], b[j]);
  }
  for (int i = 0; i < nb; ++i) {
    mean_b[i] = mean_[b[i]];
    for (int j = 0; j < nb; ++j) s_bb(i, j) = covariance_(b[i], b[j]);
  }
  if (nb == 0) return MakeWithJitter(std::move(mean_a), std::move(s_aa));
  const Eigen::LLT<Eigen::MatrixXd> llt_bb(s_bb);
  // gain K = S_ab S_bb^-1 (na x nb).
  const Eigen::MatrixXd gain = llt_bb.solve(s_ab.transpose()).transpose();
  Eigen::VectorXd mean = mean_a + gain * (values - mean_b);
  Eigen::MatrixXd cov = s_aa - gain * s_ab.transpose();
  return MakeWithJitter(std::move(mean), std::move(cov));
}

Gaussian Gaussian::Affine(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) const {
  assert(A.cols() == dim() && A.rows() == b.size());
  return MakeWithJitter(A * mean_ + b, A * covariance_ * A.transpose());
}

Eigen::VectorXd Gaussian::Sample(std::mt19937_64& rng) const {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd e(dim());
  for (int i = 0; i < dim(); ++i) e[i] = normal(rng);
  return mean_ + l_.triangularView<Eigen::Lower>() * e;
}

std::vector<int> ComplementDims(int dim, const std::vector<int>& dims) {
  std::vector<bool> taken(dim, false);
  for (int d : dims) {
    assert(d >= 0 && d < dim);
    taken[d] = true;
  }
  std::vector<int> rest;
  for (int i = 0; i < dim; ++i) {
    if (!taken[i]) rest.push_back(i);
  }
  return rest;
}

}  // namespace dgmm
