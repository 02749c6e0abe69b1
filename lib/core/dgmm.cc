#include "core/dgmm.h"

#include "core/log_sum_exp.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace dgmm {
namespace {

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

// 2^(j / 128), j = 0..127.
const std::array<double, 128> kExp2Table = [] {
  std::array<double, 128> t;
  for (int j = 0; j < 128; ++j) t[j] = std::exp2(j / 128.0);
  return t;
}();

// exp(a) for a <= 0 within 2 ulp of std::exp, inline and without errno, so that the K - 1 of a
// component draw overlap (they are on its critical path): a = (128 k + j) ln 2 / 128 + r with
// |r| <= ln 2 / 256, exp(a) = 2^k 2^(j / 128) e^r, e^r by its degree-5 Taylor polynomial (error
// under r^6 / 720 < 1e-18) in a short chain (Estrin's scheme). 0 below -708 (exp(a) < 2^-1021).
double ExpNonPositive(double a) {
  if (!(a >= -708.0)) return 0.0;
  constexpr double kInvLn2x128 = 184.66496523378731, kShift = 6755399441055744.0;  // 1.5 * 2^52
  constexpr double kLn2Hi = 0.6931471803691238 / 128, kLn2Lo = 1.9082149292705877e-10 / 128;
  const double shifted = a * kInvLn2x128 + kShift;  // 128 k + j in the low bits
  const double n = shifted - kShift;
  const double r = (a - n * kLn2Hi) - n * kLn2Lo;
  std::int64_t bits;
  std::memcpy(&bits, &shifted, sizeof bits);
  const std::int64_t n_int = bits - 0x4338000000000000;  // 128 k + j, two's complement
  const std::int64_t scale_bits = ((n_int >> 7) + 1023) << 52;  // 2^k
  double scale;
  std::memcpy(&scale, &scale_bits, sizeof scale);
  const double r2 = r * r;
  const double p = (1.0 + r) + r2 * ((0.5 + r * (1.0 / 6)) + r2 * (1.0 / 24 + r * (1.0 / 120)));
  return kExp2Table[n_int & 127] * p * scale;
}

}  // namespace

Dgmm::Dgmm(int dim, DgmmOptions options) : dim_(dim), options_(std::move(options)), mixture_(dim) {
  assert(dim > 0);
  assert(options_.IsValid(dim, nullptr));
  initial_diagonal_ = options_.ResolvedInitialDiagonal(dim);
}

Eigen::MatrixXd Dgmm::SampleCovariance(int i) const {
  const DgmmComponentStats& s = stats_[i];
  assert(s.count >= 2);
  return s.scatter / static_cast<double>(s.count - 1);
}

Eigen::MatrixXd Dgmm::FlooredCovariance(const DgmmComponentStats& stats) const {
  Eigen::MatrixXd cov;
  FloorInto(stats, &cov);
  return cov;
}

void Dgmm::CovarianceCoefficients(std::int64_t count, double* scatter_scale,
                                  double* prior_weight) const {
  const double n = static_cast<double>(count);
  *scatter_scale = 0.0;
  *prior_weight = 0.0;
  using Rule = DgmmOptions::CovarianceRule;
  switch (options_.covariance_rule) {
    case Rule::kLiteral:  // eq. 13: M2 / (n - 1); S0 until a second sample arrives
      if (count < 2) {
        *prior_weight = 1.0;
      } else {
        *scatter_scale = 1.0 / (n - 1.0);
      }
      break;
    case Rule::kBlend: {  // (M2 + nu S0) / (n - 1 + nu), nu = max(0, d + 1 - n)
      const double nu = std::max(0.0, dim_ + 1.0 - n);
      *scatter_scale = 1.0 / (n - 1.0 + nu);
      *prior_weight = nu * *scatter_scale;
      break;
    }
    case Rule::kPrior: {  // (M2 + nu0 S0) / (n + nu0)
      const double nu0 = options_.prior_pseudo_count;
      *scatter_scale = 1.0 / (n + nu0);
      *prior_weight = nu0 * *scatter_scale;
      break;
    }
  }
}

void Dgmm::FloorInto(const DgmmComponentStats& stats, Eigen::MatrixXd* cov) const {
  double scatter_scale, prior_weight;  // cov = M2 * scatter_scale + prior_weight * S0 + floor I
  CovarianceCoefficients(stats.count, &scatter_scale, &prior_weight);
  cov->resize(dim_, dim_);  // no reallocation when already dim x dim
  *cov = stats.scatter * scatter_scale;
  for (int i = 0; i < dim_; ++i) {
    (*cov)(i, i) += prior_weight * initial_diagonal_[i] + options_.covariance_floor;
  }
}

double Dgmm::MaxLogDensity() const {
  if (!max_valid_) {
    if (mixture_.empty()) {
      max_log_density_ = kNegInf;
    } else {
      // Searching from every mean costs O(K^2) per call, O(N^3) over a fit that starts a
      // component per sample. Between full searches (whenever K has doubled) only the last mode
      // and the means of components changed since the last search are starting points: the
      // unchanged components scale uniformly by W_old / W_new, so only the changed ones can
      // raise a mode above the last one (docs/reliability.md, "Bounded work").
      const int k = mixture_.size();
      std::vector<Eigen::VectorXd> starts;
      if (last_mode_.size() != dim_ || k >= 2 * std::max(full_search_size_, 1)) {
        for (int i = 0; i < k; ++i) starts.push_back(mixture_.component(i).mean());
        full_search_size_ = k;
      } else {
        starts.push_back(last_mode_);
        for (int i = 0; i < k; ++i) {
          if (i >= static_cast<int>(searched_weights_.size()) ||
              searched_weights_[i] != mixture_.weight(i)) {
            starts.push_back(mixture_.component(i).mean());
          }
        }
      }
      Mixture::Mode mode = mixture_.MaxDensityFrom(starts);
      max_log_density_ = mode.log_density;
      last_mode_ = std::move(mode.x);
      searched_weights_ = mixture_.weights();
    }
    max_valid_ = true;
  }
  return max_log_density_;
}

double Dgmm::PeakLogDensityBound() const {
  // p(x) <= sum_i w_i/W max N_i = sum_i w_i/W (2 pi)^(-d/2) det(S_i)^(-1/2).
  constexpr double kLog2Pi = 1.8378770664093454835606594728112;
  // Each term is cheap (cached log-determinant): recomputed per pass, no buffer on AddSample's path.
  const double lse = LogSumExpOf(mixture_.size(), [this](int i) {
    return std::log(mixture_.weight(i)) - 0.5 * mixture_.component(i).log_det();
  });
  return lse - std::log(mixture_.total_weight()) - 0.5 * dim_ * kLog2Pi;
}

AddSampleResult Dgmm::AddSample(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng) {
  assert(x.size() == dim_ && x.allFinite());
  if (options_.variant == DgmmOptions::Variant::kImproved) return AddSampleImproved(x, rng);
  return AddSampleFaithful(x, rng);
}

AddSampleResult Dgmm::DecideMerge(const Eigen::Ref<const Eigen::VectorXd>& x,
                                  std::mt19937_64& rng) {
  AddSampleResult result;
  // exp(-k n) underflows to exactly 0 beyond k n = 745.2; skip the call there.
  const double kn = options_.k * static_cast<double>(num_samples_);
  const double decay = kn > 746.0 ? 0.0 : std::exp(-kn);
  const bool at_cap = options_.max_components > 0 && mixture_.size() >= options_.max_components;
  if (at_cap || (!mixture_.empty() && 1.0 - decay == 1.0)) {
    // At the cap every sample merges (bounded work: no density needed); and once t = 1 in
    // floating point, r < t holds for every r in [0, 1): the merge is certain, r is not drawn.
    max_components_hit_ = max_components_hit_ || at_cap;
    result.threshold = 1.0;
    result.merged = true;
    return result;
  }
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double r = uniform(rng);
  if (mixture_.empty()) {
    // p(x) = 0 for an empty model: d = 0 and t = 1 - exp(0) = 0, so r < t never holds.
    result.threshold = 0.0;
    result.density_evaluated = true;
  } else {
    // t = 1 - (1 - d) exp(-k n) >= 1 - exp(-k n) for any d in [0, 1]: below that bound the
    // sample merges whatever d is, so d (and the max-density search) is computed only above it.
    result.threshold = 1.0 - decay;
    if (!(r < result.threshold)) {
      const double log_p = mixture_.LogDensity(x);
      // Bounds lo <= log max p <= hi decide most samples without the mode search (exactly:
      // t is increasing in d): lo = log p at the last mode found (or at x itself), hi = log of
      // the sum of each component's peak w_i N_i(mu_i) / W.
      double decided = -1.0;  // the threshold bound that decides, or -1
      if (!max_valid_) {
        double lo = log_p;
        if (last_mode_.size() == dim_) lo = std::max(lo, mixture_.LogDensity(last_mode_));
        const double hi = PeakLogDensityBound();
        const double t_lo = 1.0 - (1.0 - std::clamp(std::exp(log_p - hi), 0.0, 1.0)) * decay;
        const double t_hi = 1.0 - (1.0 - std::clamp(std::exp(log_p - lo), 0.0, 1.0)) * decay;
        if (r < t_lo) decided = t_lo;
        if (!(r < t_hi)) decided = t_hi;
      }
      if (decided >= 0) {
        result.threshold = decided;
      } else {
        const double d = std::clamp(std::exp(log_p - MaxLogDensity()), 0.0, 1.0);
        result.threshold = 1.0 - (1.0 - d) * decay;
        result.density_evaluated = true;
      }
    }
    result.merged = r < result.threshold;
  }
  return result;
}

AddSampleResult Dgmm::AddSampleFaithful(const Eigen::Ref<const Eigen::VectorXd>& x,
                                        std::mt19937_64& rng) {
  AddSampleResult result = DecideMerge(x, rng);
  if (result.merged) {
    result.component = ChooseComponent(x, rng);
    MergeInto(result.component, x);
  } else {
    result.component = StartComponent(x);
  }
  ++num_samples_;
  return result;
}

int Dgmm::StartComponent(const Eigen::Ref<const Eigen::VectorXd>& x) {
  DgmmComponentStats s;
  s.count = 1;
  s.mean = x;
  s.scatter = Eigen::MatrixXd::Zero(dim_, dim_);
  stats_.push_back(std::move(s));
  Eigen::MatrixXd cov = FlooredCovariance(stats_.back());
  mixture_.Add(1.0, Gaussian(x, std::move(cov)));
  factor_floor_.push_back(options_.covariance_floor);
  updates_since_factor_.push_back(0);
  max_valid_ = false;
  return mixture_.size() - 1;
}

void Dgmm::MergeInto(int i, const Eigen::Ref<const Eigen::VectorXd>& x) {
  // Eqs. 11-13 with w = n the sample count: w' = w + 1, mu' = mu + (x - mu) / w',
  // S' = (w - 1)/w S + (x - mu)(x - mu)^T / w'. Kept as count, mean and scatter
  // M2 = (n - 1) S, updated M2' = M2 + (w / w') delta delta^T (Welford), which is the same
  // recursion multiplied by w and keeps M2 exactly symmetric and positive semi-definite.
  DgmmComponentStats& s = stats_[i];
  const double w = static_cast<double>(s.count);
  const double w_next = w + 1.0;
  delta_scratch_ = x - s.mean;
  s.mean.noalias() += delta_scratch_ / w_next;
  // M2 += e e^T with e = sqrt(c) delta, c = w / w': each entry e_r e_c, so the scatter stays
  // bitwise symmetric (the products commute).
  update_weight_ = w / w_next;
  update_scratch_ = std::sqrt(update_weight_) * delta_scratch_;
  const double* e = update_scratch_.data();
  double* m2 = s.scatter.data();
  for (int col = 0; col < dim_; ++col) {
    for (int row = 0; row < dim_; ++row, ++m2) *m2 += e[row] * e[col];
  }
  s.count += 1;
  mixture_.SetWeight(i, static_cast<double>(s.count));
  if (!RankOneRefresh(i)) RefreshComponent(i);
  whitened_component_ = -1;  // its factor changed
}

bool Dgmm::RankOneRefresh(int i) {
  // Every rule is cov(n) = a_n M2 + b_n S0 + f I. With alpha = a_{n+1} / a_n and
  // b_{n+1} = alpha b_n (the prior rule always; literal and blend once n > d):
  //   cov(n+1) = alpha cov(n) + a_{n+1} e e^T + (1 - alpha) f I   (e from MergeInto),
  // a rank-one update of the cached factor (O(d^2) instead of O(d^3)) except for the last term.
  // It is dropped while the floor g inside the factor stays above f / 1.01, so the floor sags
  // by under 1% until the next factorisation, which restores g = f. Factorising again after
  // kMaxUpdates updates bounds the round-off the updates accumulate.
  constexpr int kMaxUpdates = 1024;
  constexpr double kFloorSag = 1.01;
  const DgmmComponentStats& s = stats_[i];
  double a_old, b_old, a_new, b_new;
  CovarianceCoefficients(s.count - 1, &a_old, &b_old);
  CovarianceCoefficients(s.count, &a_new, &b_new);
  if (!(a_old > 0.0) || updates_since_factor_[i] >= kMaxUpdates) return false;
  const double alpha = a_new / a_old;
  if (std::abs(b_new - alpha * b_old) > 1e-12 * std::max(b_new, alpha * b_old)) return false;
  const double floor = alpha * factor_floor_[i];
  if (floor * kFloorSag < options_.covariance_floor) return false;
  // a_{n+1} e e^T = rho delta delta^T with rho = a_{n+1} c; L^-1 delta from ChooseComponent when
  // it has just computed it.
  const double rho = a_new * update_weight_;
  const double* l_inv_delta =
      whitened_component_ == i ? &whitened_[static_cast<std::size_t>(i) * dim_] : nullptr;
  if (!mixture_.mutable_component(i).ScaleAndRankOneUpdate(s.mean, alpha, delta_scratch_, rho,
                                                           l_inv_delta)) {
    return false;
  }
  factor_floor_[i] = floor;
  ++updates_since_factor_[i];
  max_valid_ = false;
  return true;
}

void Dgmm::RefreshComponent(int i) {
  FloorInto(stats_[i], &covariance_scratch_);
  Gaussian& g = mixture_.mutable_component(i);
  max_valid_ = false;
  factor_floor_[i] = options_.covariance_floor;
  updates_since_factor_[i] = 0;
  if (g.SetInPlace(stats_[i].mean, covariance_scratch_)) return;
  // Round-off (or floor = 0 with degenerate samples): add a growing multiple of S0's diagonal.
  for (double jitter = 1e-12; jitter <= 1.0; jitter *= 10) {
    Eigen::MatrixXd c = covariance_scratch_;
    c.diagonal() += jitter * initial_diagonal_;
    if (g.SetInPlace(stats_[i].mean, c)) return;
  }
  // Cannot happen for finite inputs (jitter 1 * S0 alone is PD); keep S0 as a last resort.
  g.SetInPlace(stats_[i].mean, initial_diagonal_.asDiagonal().toDenseMatrix());
}

int Dgmm::ChooseComponent(const Eigen::Ref<const Eigen::VectorXd>& x, std::mt19937_64& rng) {
  // P(i) = w_i g_i(x) / sum_j w_j g_j(x), g_i = exp(-1/2 m_i^2) (max-normalised, Algorithm 2).
  // g_i is scaled by exp(1/2 min_j m_j^2) so that a sample far from every component still picks
  // the nearest one (the nearest gets g = 1; weights are counts >= 1, so nothing overflows).
  const int k = mixture_.size();
  if (k == 1) return 0;  // nothing to draw
  log_choice_.resize(k);
  whitened_.resize(static_cast<std::size_t>(k) * dim_);
  Gaussian::WhitenEach(mixture_.components(), x, whitened_.data(), log_choice_.data());
  double m = kNegInf;
  for (int i = 0; i < k; ++i) {
    log_choice_[i] *= -0.5;
    m = std::max(m, log_choice_[i]);
  }
  double total = 0.0;
  for (int i = 0; i < k; ++i) {
    // The nearest (a = 0) needs no exp; a branch on it is faster than none (it is predicted).
    const double a = log_choice_[i] - m;
    log_choice_[i] = mixture_.weight(i) * (a == 0.0 ? 1.0 : ExpNonPositive(a));
    total += log_choice_[i];
  }
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double u = uniform(rng) * total;
  double cumulative = 0.0;
  for (int i = 0; i < k; ++i) {
    cumulative += log_choice_[i];
    if (u < cumulative) return whitened_component_ = i;
  }
  // u == total by round-off: the last component with non-zero probability.
  for (int i = k - 1; i >= 0; --i) {
    if (log_choice_[i] > 0) return whitened_component_ = i;
  }
  return whitened_component_ = k - 1;
}

}  // namespace dgmm
