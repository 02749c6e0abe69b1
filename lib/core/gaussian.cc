#include "core/gaussian.h"

#include <cassert>
#include <cmath>
#include <mutex>
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

// The hot loops of the DGMM update, written once with the dimension as a template parameter: for
// d <= 12 the compiler unrolls them and keeps the work vectors in registers (0 means "dimension at
// run time"). `l` is the column-major factor, `inv_diag` its 1 / L_jj.

// z_n = L_n^-1 (x - mean_n) by forward substitution, column by column, for N factors at once (their
// dependency chains are independent, so they overlap); m2[n] = |z_n|^2.
template <int D, int N>
void ForwardSubstitute(int d, const double* const* l, const double* const* inv_diag,
                       const double* x, const double* const* mean, double* const* z, double* m2) {
  if constexpr (D > 0) d = D;
  double u[N][D > 0 ? D : kMaxStackDims];
  double sum[N];
#pragma GCC unroll 4
  for (int n = 0; n < N; ++n) {
    sum[n] = 0.0;
    for (int i = 0; i < d; ++i) u[n][i] = x[i] - mean[n][i];
  }
#pragma GCC unroll 12
  for (int j = 0; j < d; ++j) {
#pragma GCC unroll 4
    for (int n = 0; n < N; ++n) {
      const double zj = u[n][j] * inv_diag[n][j];
      z[n][j] = zj;
      sum[n] += zj * zj;
      const double* col = l[n] + static_cast<std::ptrdiff_t>(j) * d;
#pragma GCC unroll 12
      for (int i = j + 1; i < d; ++i) u[n][i] -= col[i] * zj;
    }
  }
  for (int n = 0; n < N; ++n) m2[n] = sum[n];
}

// L' L'^T = alpha L L^T + rho w w^T by L' = sqrt(alpha) L M with M M^T = I + p p^T,
// p = sqrt(rho / alpha) L^-1 w. M is known in closed form (Gill, Golub, Murray & Saunders 1974):
// with b_0 = 1, b_k = b_(k-1) + p_k^2, M_kk = sqrt(b_k / b_(k-1)) and
// M_ik = p_i p_k / sqrt(b_k b_(k-1)) for i > k. Written with z = L^-1 w,
// beta_k = alpha b_k = alpha + rho sum_(j <= k) z_j^2 (beta_-1 = alpha), s_k = sqrt(beta_k),
// t_k = 1 / s_k and r = w - sum_(j <= k) L_:j z_j (the forward substitution's residual), column k
// of L' is c_k (s_k L_:k + rho z_k t_k r) with c_k = sqrt(alpha) t_(k-1) (c_0 = 1): the first
// column waits for no square root of alpha or rho. One pass; a column's square root and division
// run beside the next columns' work. z: L^-1 w when the caller has it (then no column waits for
// the previous one), else null and z_k = r_k / L_kk (a chain from column to column).
// Writes L' (lower, upper zeroed) and 1 / L'_kk; returns beta_(d-1) = alpha det(I + p p^T).
template <int D>
double RankOneUpdate(int d, const double* l, double* l_new, const double* inv_diag,
                     double* inv_diag_new, double alpha, double rho, const double* w,
                     const double* z) {
  if constexpr (D > 0) d = D;
  const double root_alpha = std::sqrt(alpha), inv_root_alpha = 1.0 / root_alpha;
  double r[D > 0 ? D : kMaxStackDims];
#pragma GCC unroll 12
  for (int i = 0; i < d; ++i) r[i] = w[i];
  double beta = alpha, s_prev = root_alpha, t_prev = inv_root_alpha;
#pragma GCC unroll 12
  for (int k = 0; k < d; ++k) {
    const double* col = l + static_cast<std::ptrdiff_t>(k) * d;
    double* col_new = l_new + static_cast<std::ptrdiff_t>(k) * d;
    const double zk = z ? z[k] : r[k] * inv_diag[k];
    beta += rho * zk * zk;
    const double s = std::sqrt(beta), t = 1.0 / s;
    const double c = k == 0 ? 1.0 : root_alpha * t_prev;  // c_k
    const double m_kk = c * s, gamma = c * rho * zk * t;
#pragma GCC unroll 12
    for (int i = 0; i < k; ++i) col_new[i] = 0.0;
    col_new[k] = col[k] * m_kk;
    inv_diag_new[k] = inv_diag[k] * t * (k == 0 ? 1.0 : s_prev * inv_root_alpha);  // / c_k
#pragma GCC unroll 12
    for (int i = k + 1; i < d; ++i) {
      r[i] -= col[i] * zk;
      col_new[i] = col[i] * m_kk + gamma * r[i];
    }
    s_prev = s, t_prev = t;
  }
  return beta;
}

// ForwardSubstitute for one and for two factors, for DGMM_DISPATCH_DIM.
template <int D>
void ForwardSubstituteOne(int d, const double* l, const double* inv_diag, const double* x,
                          const double* mean, double* z, double* m2) {
  ForwardSubstitute<D, 1>(d, &l, &inv_diag, x, &mean, &z, m2);
}
template <int D>
void ForwardSubstituteTwo(int d, const double* const* l, const double* const* inv_diag,
                          const double* x, const double* const* mean, double* const* z,
                          double* m2) {
  ForwardSubstitute<D, 2>(d, l, inv_diag, x, mean, z, m2);
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

Gaussian::Gaussian(const Gaussian& other)
    : mean_(other.mean_),
      covariance_(other.covariance()),
      l_(other.l_),
      log_det_(other.log_det_),
      det_factor_(other.det_factor_),
      inv_diag_(other.inv_diag_) {}

Gaussian::Gaussian(Gaussian&& other) noexcept
    : mean_(std::move(other.mean_)),
      covariance_(std::move(other.covariance_)),
      covariance_stale_(other.covariance_stale_.load(std::memory_order_relaxed)),
      l_(std::move(other.l_)),
      log_det_(other.log_det_),
      det_factor_(other.det_factor_),
      inv_diag_(std::move(other.inv_diag_)) {}

Gaussian& Gaussian::operator=(const Gaussian& other) {
  if (this != &other) *this = Gaussian(other);
  return *this;
}

Gaussian& Gaussian::operator=(Gaussian&& other) noexcept {
  mean_ = std::move(other.mean_);
  covariance_ = std::move(other.covariance_);
  covariance_stale_.store(other.covariance_stale_.load(std::memory_order_relaxed),
                          std::memory_order_relaxed);
  l_ = std::move(other.l_);
  log_det_ = other.log_det_;
  det_factor_ = other.det_factor_;
  inv_diag_ = std::move(other.inv_diag_);
  return *this;
}

void Gaussian::RestoreCovariance() const {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!covariance_stale_.load(std::memory_order_relaxed)) return;  // another thread did it
  const int d = dim();
  for (int j = 0; j < d; ++j) {  // c_ij = c_ji = sum_(k <= j) L_ik L_jk
    for (int i = j; i < d; ++i) {
      covariance_(i, j) = covariance_(j, i) = l_.row(i).head(j + 1).dot(l_.row(j).head(j + 1));
    }
  }
  covariance_stale_.store(false, std::memory_order_release);
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
  covariance_stale_.store(false, std::memory_order_relaxed);
  l_ = std::move(l);
  log_det_ = 2.0 * l_.diagonal().array().log().sum();
  det_factor_ = 1.0;
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
  covariance_stale_.store(false, std::memory_order_relaxed);
  log_det_ = 2.0 * l_.diagonal().array().log().sum();
  det_factor_ = 1.0;
  inv_diag_ = l_.diagonal().cwiseInverse();
  return true;
}

bool Gaussian::ScaleAndRankOneUpdate(const Eigen::Ref<const Eigen::VectorXd>& mean, double alpha,
                                     const Eigen::Ref<const Eigen::VectorXd>& v, double rho,
                                     const double* l_inv_v) {
  const int d = dim();
  assert(mean.size() == d && v.size() == d);
  if (!(alpha > 0.0) || !std::isfinite(alpha) || !(rho >= 0.0) || !std::isfinite(rho) ||
      !v.allFinite() || !mean.allFinite()) {
    return false;
  }
  if (d > kMaxStackDims) {  // rare: refactorise the updated covariance
    const Eigen::MatrixXd vv = v * v.transpose();  // bitwise symmetric: v_i v_j = v_j v_i
    const Eigen::MatrixXd c = alpha * covariance() + rho * vv;
    return SetInPlace(mean, c);
  }
  scratch_.resize(d, d);  // the new factor
  inv_diag_scratch_.resize(d);
  const double beta = DGMM_DISPATCH_DIM(d, RankOneUpdate, d, l_.data(), scratch_.data(),
                                        inv_diag_.data(), inv_diag_scratch_.data(), alpha, rho,
                                        v.data(), l_inv_v);
  // det(alpha L L^T + rho v v^T) = alpha^d det(L L^T) (1 + |p|^2) (matrix determinant lemma); the
  // factor is multiplied into det_factor_ and its log taken only when that leaves [1e-100, 1e100].
  double scale = beta;  // alpha^d (1 + |p|^2) = alpha^(d-1) beta, by multiplication (pow is slow)
  for (int i = 1; i < d; ++i) scale *= alpha;
  double det_factor = det_factor_ * scale, log_det = log_det_;
  if (!(det_factor > 1e-100 && det_factor < 1e100)) {
    log_det += std::log(det_factor_) + std::log(scale);
    det_factor = 1.0;
  }
  // Finite inputs give a finite result unless something overflowed, which shows on the diagonal
  // (sum_k L'_ik^2 = covariance'_ii) or in log det.
  if (!std::isfinite(log_det) || !scratch_.diagonal().allFinite()) return false;
  l_.swap(scratch_);
  inv_diag_.swap(inv_diag_scratch_);
  mean_ = mean;
  covariance_stale_.store(true, std::memory_order_relaxed);  // covariance() rebuilds it
  log_det_ = log_det;
  det_factor_ = det_factor;
  return true;
}

double Gaussian::SquaredMahalanobis(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  assert(x.size() == mean_.size());
  const int d = dim();
  if (d <= kMaxStackDims && x.innerStride() == 1) {
    double z[kMaxStackDims], m2;
    DGMM_DISPATCH_DIM(d, ForwardSubstituteOne, d, l_.data(), inv_diag_.data(), x.data(),
                      mean_.data(), z, &m2);
    return m2;
  }
  Eigen::VectorXd u = x - mean_;
  l_.triangularView<Eigen::Lower>().solveInPlace(u);
  return u.squaredNorm();
}

void Gaussian::WhitenEach(const std::vector<Gaussian>& gaussians,
                          const Eigen::Ref<const Eigen::VectorXd>& x, double* z, double* m2) {
  const int k = static_cast<int>(gaussians.size()), d = static_cast<int>(x.size());
  if (d > kMaxStackDims || x.innerStride() != 1) {
    for (int i = 0; i < k; ++i) {
      Eigen::Map<Eigen::VectorXd> zi(z + static_cast<std::ptrdiff_t>(i) * d, d);
      zi = x - gaussians[i].mean_;
      gaussians[i].l_.triangularView<Eigen::Lower>().solveInPlace(zi);
      m2[i] = zi.squaredNorm();
    }
    return;
  }
  int i = 0;
  for (; i + 2 <= k; i += 2) {  // two at a time: their substitutions overlap
    const Gaussian &g0 = gaussians[i], &g1 = gaussians[i + 1];
    const double* l[2] = {g0.l_.data(), g1.l_.data()};
    const double* inv_diag[2] = {g0.inv_diag_.data(), g1.inv_diag_.data()};
    const double* mean[2] = {g0.mean_.data(), g1.mean_.data()};
    double* zs[2] = {z + static_cast<std::ptrdiff_t>(i) * d,
                     z + static_cast<std::ptrdiff_t>(i + 1) * d};
    DGMM_DISPATCH_DIM(d, ForwardSubstituteTwo, d, l, inv_diag, x.data(), mean, zs, m2 + i);
  }
  if (i < k) {
    const Gaussian& g = gaussians[i];
    DGMM_DISPATCH_DIM(d, ForwardSubstituteOne, d, g.l_.data(), g.inv_diag_.data(), x.data(),
                      g.mean_.data(), z + static_cast<std::ptrdiff_t>(i) * d, m2 + i);
  }
}

double Gaussian::LogDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  return -0.5 * (dim() * kLog2Pi + log_det() + SquaredMahalanobis(x));
}

Eigen::VectorXd Gaussian::LogDensity(const Eigen::Ref<const Eigen::MatrixXd>& X) const {
  assert(X.rows() == mean_.size());
  Eigen::MatrixXd u = X.colwise() - mean_;
  l_.triangularView<Eigen::Lower>().solveInPlace(u);
  const double c = dim() * kLog2Pi + log_det();
  return (-0.5 * (u.colwise().squaredNorm().array() + c)).transpose();
}

double Gaussian::ScaledDensity(const Eigen::Ref<const Eigen::VectorXd>& x) const {
  return std::exp(-0.5 * SquaredMahalanobis(x));
}

Gaussian Gaussian::Marginal(const std::vector<int>& dims) const {
  const Eigen::MatrixXd& c = covariance();
  const int k = static_cast<int>(dims.size());
  Eigen::VectorXd m(k);
  Eigen::MatrixXd s(k, k);
  for (int i = 0; i < k; ++i) {
    assert(dims[i] >= 0 && dims[i] < dim());
    m[i] = mean_[dims[i]];
    for (int j = 0; j < k; ++j) s(i, j) = c(dims[i], dims[j]);
  }
  return MakeWithJitter(std::move(m), std::move(s));
}

Gaussian Gaussian::Conditional(const std::vector<int>& given_dims,
                               const Eigen::Ref<const Eigen::VectorXd>& values) const {
  const Eigen::MatrixXd& c = covariance();
  assert(static_cast<int>(given_dims.size()) == values.size());
  const std::vector<int> a = ComplementDims(dim(), given_dims);
  const std::vector<int>& b = given_dims;
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  Eigen::VectorXd mean_a(na), mean_b(nb);
  Eigen::MatrixXd s_aa(na, na), s_ab(na, nb), s_bb(nb, nb);
  for (int i = 0; i < na; ++i) {
    mean_a[i] = mean_[a[i]];
    for (int j = 0; j < na; ++j) s_aa(i, j) = c(a[i], a[j]);
    for (int j = 0; j < nb; ++j) s_ab(i, j) = c(a[i], b[j]);
  }
  for (int i = 0; i < nb; ++i) {
    mean_b[i] = mean_[b[i]];
    for (int j = 0; j < nb; ++j) s_bb(i, j) = c(b[i], b[j]);
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
  return MakeWithJitter(A * mean_ + b, A * covariance() * A.transpose());
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
