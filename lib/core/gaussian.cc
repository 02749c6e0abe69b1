#include "core/gaussian.h"

#include <cassert>
#include <cmath>
#include <numbers>

namespace dgmm {
namespace {

// log(2 pi).
constexpr double kLog2Pi = 1.8378770664093454835606594728112;
// Dimensions up to which the hot loops work on the stack (beyond: Eigen, heap).
constexpr int kMaxStackDims = 32;

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

// The two hot loops of the DGMM update, written once with the dimension as a template
// parameter: for d <= kFixedDims the compiler unrolls them and keeps the work vector in registers
// (0 means "dimension at run time"). `l` is the column-major factor, `inv_diag` its 1 / L_jj.

// m^2 = |L^-1 (x - mean)|^2 by forward substitution, column by column.
template <int D>
double ForwardSquaredNorm(int d, const double* l, const double* inv_diag, const double* x,
                          const double* mean) {
  if constexpr (D > 0) d = D;
  double u[D > 0 ? D : kMaxStackDims];
  for (int i = 0; i < d; ++i) u[i] = x[i] - mean[i];
  double m2 = 0.0;
#pragma GCC unroll 12
  for (int j = 0; j < d; ++j) {
    const double uj = u[j] * inv_diag[j];
    m2 += uj * uj;
    const double* col = l + static_cast<std::ptrdiff_t>(j) * d;
#pragma GCC unroll 12
    for (int i = j + 1; i < d; ++i) u[i] -= col[i] * uj;
  }
  return m2;
}

// L' = sqrt(alpha) L M with M M^T = I + p p^T, p = L^-1 x, x = w / sqrt(alpha), so that
// L' L'^T = alpha L L^T + w w^T. M is known in closed form (Gill, Golub, Murray & Saunders 1974):
// with b_0 = 1, b_k = b_(k-1) + p_k^2, M_kk = sqrt(b_k / b_(k-1)) and
// M_ik = p_i p_k / sqrt(b_k b_(k-1)) for i > k, so column k of L M is
// L_:k M_kk + p_k / sqrt(b_k b_(k-1)) * (x - sum_(j <= k) L_:j p_j), and that bracket is the
// residual of the forward substitution for p. One pass: the only dependency chain from column to
// column is the substitution's multiply-add; the square roots and divisions run side by side.
// Writes L' (lower, upper zeroed) and 1 / L'_kk; returns b_d = 1 + |p|^2 (det(I + p p^T)).
template <int D>
double RankOneUpdate(int d, const double* l, double* l_new, const double* inv_diag,
                     double* inv_diag_new, double alpha, const double* w) {
  if constexpr (D > 0) d = D;
  const double root_alpha = std::sqrt(alpha), inv_root_alpha = 1.0 / root_alpha;
  double u[D > 0 ? D : kMaxStackDims];  // residual x - sum_(j <= k) L_:j p_j
#pragma GCC unroll 12
  for (int i = 0; i < d; ++i) u[i] = w[i] * inv_root_alpha;
  double b_prev = 1.0, inv_root_b_prev = 1.0, root_b_prev = 1.0;
#pragma GCC unroll 12
  for (int k = 0; k < d; ++k) {
    const double* col = l + static_cast<std::ptrdiff_t>(k) * d;
    double* col_new = l_new + static_cast<std::ptrdiff_t>(k) * d;
    const double p = u[k] * inv_diag[k];
    const double b = b_prev + p * p;
    const double root_b = std::sqrt(b), inv_root_b = 1.0 / root_b;
    const double m_kk = root_alpha * root_b * inv_root_b_prev;  // sqrt(alpha) M_kk
    const double gamma = root_alpha * p * inv_root_b * inv_root_b_prev;
#pragma GCC unroll 12
    for (int i = 0; i < k; ++i) col_new[i] = 0.0;
    col_new[k] = col[k] * m_kk;
    inv_diag_new[k] = inv_diag[k] * inv_root_alpha * root_b_prev * inv_root_b;
#pragma GCC unroll 12
    for (int i = k + 1; i < d; ++i) {
      u[i] -= col[i] * p;
      col_new[i] = col[i] * m_kk + gamma * u[i];
    }
    b_prev = b, inv_root_b_prev = inv_root_b, root_b_prev = root_b;
  }
  return b_prev;
}

// Calls Kernel<D> for D = d when d <= kFixedDims, else Kernel<0>.
#define DGMM_DISPATCH_DIM(d, KERNEL, ...)                                            \
  [&] {                                                                               \
    switch (d) {                                                                      \
      case 1: return KERNEL<1>(__VA_ARGS__);                                          \
      case 2: return KERNEL<2>(__VA_ARGS__);                                          \
      case 3: return KERNEL<3>(__VA_ARGS__);                                          \
      case 4: return KERNEL<4>(__VA_ARGS__);                                          \
      case 5: return KERNEL<5>(__VA_ARGS__);                                          \
      case 6: return KERNEL<6>(__VA_ARGS__);                                          \
      case 7: return KERNEL<7>(__VA_ARGS__);                                          \
      case 8: return KERNEL<8>(__VA_ARGS__);                                          \
      case 9: return KERNEL<9>(__VA_ARGS__);                                          \
      case 10: return KERNEL<10>(__VA_ARGS__);                                        \
      case 11: return KERNEL<11>(__VA_ARGS__);                                        \
      case 12: return KERNEL<12>(__VA_ARGS__);                                        \
      default: return KERNEL<0>(__VA_ARGS__);                                         \
    }                                                                                 \
  }()

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
  inv_diag_ = l_.diagonal().cwiseInverse();
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
  inv_diag_ = l_.diagonal().cwiseInverse();
  return true;
}

bool Gaussian::ScaleAndRankOneUpdate(const Eigen::Ref<const Eigen::VectorXd>& mean, double alpha,
                                     const Eigen::Ref<const Eigen::VectorXd>& v) {
  const int d = dim();
  assert(mean.size() == d && v.size() == d);
  if (!(alpha > 0.0) || !std::isfinite(alpha) || !v.allFinite() || !mean.allFinite() ||
      v.innerStride() != 1) {
    return false;
  }
  if (d > kMaxStackDims) {  // rare: refactorise the updated covariance
    Eigen::MatrixXd c = alpha * covariance_ + v * v.transpose();
    return SetInPlace(mean, c);
  }
  scratch_.resize(d, d);  // the new factor
  inv_diag_scratch_.resize(d);
  const double b = DGMM_DISPATCH_DIM(d, RankOneUpdate, d, l_.data(), scratch_.data(),
                                     inv_diag_.data(), inv_diag_scratch_.data(), alpha, v.data());
  // det(alpha L L^T + w w^T) = alpha^d det(L L^T) (1 + |p|^2) (matrix determinant lemma).
  double scale = b;  // alpha^d b, by multiplication (pow is slow)
  for (int i = 0; i < d; ++i) scale *= alpha;
  const double log_det = log_det_ + std::log(scale);
  // Finite inputs give a finite result unless something overflowed, which shows on the diagonal
  // (sum_k L'_ik^2 = covariance'_ii) or in log det.
  if (!std::isfinite(log_det) || !scratch_.diagonal().allFinite()) return false;
  l_.swap(scratch_);
  inv_diag_.swap(inv_diag_scratch_);
  mean_ = mean;
  // alpha c_ij + v_i v_j is bitwise symmetric because c is: the products commute.
  double* c = covariance_.data();
  for (int col = 0; col < d; ++col) {
    for (int row = 0; row < d; ++row, ++c) *c = alpha * *c + v[row] * v[col];
  }
  log_det_ = log_det;
  return true;
}

double Gaussian::SquaredMahalanobis(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  assert(x.size() == mean_.size());
  const int d = dim();
  if (d <= kMaxStackDims && x.innerStride() == 1) {
    return DGMM_DISPATCH_DIM(d, ForwardSquaredNorm, d, l_.data(), inv_diag_.data(), x.data(),
                             mean_.data());
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
