#include "em/em_kernels.h"

#include <algorithm>
#include <cassert>
#include <cstring>

#include "util/target_clones.h"

namespace dgmm::em_internal {
namespace {

// m2_i = |U^T x_i - shift|^2 for the b samples of a block (cols[a]: column a of the block, U:
// d x d upper triangular, column-major). D fixes d at compile time so that the loops over
// dimensions unroll and the loop over samples vectorises.
template <int D>
DGMM_ALWAYS_INLINE void SquaredMahalanobisBlockFixed(const double* const* cols, Eigen::Index b, const double* U,
                                  const double* shift, double* __restrict m2) {
  const double* __restrict c[D];
  for (int a = 0; a < D; ++a) c[a] = cols[a];
  double u[D * D], s[D];
  for (int a = 0; a < D * D; ++a) u[a] = U[a];
  for (int a = 0; a < D; ++a) s[a] = shift[a];
  // Four samples at a time in a GCC/Clang vector (two SSE2 or one AVX register), then the tail.
  typedef double Lanes __attribute__((vector_size(4 * sizeof(double))));
  Eigen::Index i = 0;
  for (; i + 4 <= b; i += 4) {
    Lanes x[D];
    for (int a = 0; a < D; ++a) std::memcpy(&x[a], c[a] + i, sizeof(Lanes));
    Lanes acc = {0, 0, 0, 0};
    for (int j = 0; j < D; ++j) {
      Lanes y = x[0] * u[j * D] - s[j];
      for (int a = 1; a <= j; ++a) y += x[a] * u[a + j * D];
      acc += y * y;
    }
    std::memcpy(m2 + i, &acc, sizeof(Lanes));
  }
  for (; i < b; ++i) {
    double acc = 0;
    for (int j = 0; j < D; ++j) {
      double y = -s[j];
      for (int a = 0; a <= j; ++a) y += c[a][i] * u[a + j * D];
      acc += y * y;
    }
    m2[i] = acc;
  }
}

// WeightedMoments for d = D, in blocks of kScatterBlock samples: the block is shifted once
// (D columns in L1 cache), then each row a of the triangle accumulates its a + 1 sums (and the
// first moment) over the block in registers (4 lanes: one AVX or two SSE2 registers per sum).
constexpr Eigen::Index kScatterBlock = 256;

template <int D>
DGMM_ALWAYS_INLINE void WeightedMomentsFixed(const double* const* cols, Eigen::Index n, const double* r,
                                             const double* mean, double* first, double* cov) {
  typedef double Lanes __attribute__((vector_size(4 * sizeof(double))));
  alignas(32) double centred[D][kScatterBlock];
  double sums[D][D] = {}, firsts[D] = {};
  for (Eigen::Index i0 = 0; i0 < n; i0 += kScatterBlock) {
    const Eigen::Index b = std::min(kScatterBlock, n - i0);
    const Eigen::Index b4 = b & ~Eigen::Index{3};
    for (int a = 0; a < D; ++a) {
      for (Eigen::Index i = 0; i < b; ++i) centred[a][i] = cols[a][i0 + i] - mean[a];
    }
#pragma GCC unroll 8
    for (int a = 0; a < D; ++a) {
      Lanes acc[D], acc_first = {0, 0, 0, 0};
#pragma GCC unroll 8
      for (int c = 0; c <= a; ++c) acc[c] = Lanes{0, 0, 0, 0};
      for (Eigen::Index i = 0; i < b4; i += 4) {
        Lanes weight, w;
        std::memcpy(&weight, r + i0 + i, sizeof(Lanes));
        std::memcpy(&w, &centred[a][i], sizeof(Lanes));
        w *= weight;
        acc_first += w;
#pragma GCC unroll 8
        for (int c = 0; c <= a; ++c) {
          Lanes x;
          std::memcpy(&x, &centred[c][i], sizeof(Lanes));
          acc[c] += w * x;
        }
      }
      for (int c = 0; c <= a; ++c) {
        double tail = 0;
        for (Eigen::Index i = b4; i < b; ++i) tail += r[i0 + i] * centred[a][i] * centred[c][i];
        sums[a][c] += (acc[c][0] + acc[c][1]) + (acc[c][2] + acc[c][3]) + tail;
      }
      double tail = 0;
      for (Eigen::Index i = b4; i < b; ++i) tail += r[i0 + i] * centred[a][i];
      firsts[a] += (acc_first[0] + acc_first[1]) + (acc_first[2] + acc_first[3]) + tail;
    }
  }
  for (int a = 0; a < D; ++a) {
    first[a] += firsts[a];
    for (int c = 0; c <= a; ++c) cov[a + c * D] += sums[a][c];
  }
}

typedef double Lanes4 __attribute__((vector_size(4 * sizeof(double))));
typedef long long Ints4 __attribute__((vector_size(4 * sizeof(long long))));

// exp of four values <= 0, in place (see NormaliseBlock); below -708 the result is 0. By pointer:
// a vector passed by value would change the baseline clone's ABI.
DGMM_ALWAYS_INLINE void ExpNonPositive(Lanes4* value) {
  Lanes4 x = *value;
  const Ints4 underflow = x < -708.0;
  x = underflow ? Lanes4{-708.0, -708.0, -708.0, -708.0} : x;
  constexpr double kLog2e = 1.4426950408889634, kLn2Hi = 0.6931471803691238, kLn2Lo = 1.9082149292705877e-10;
  constexpr double kRound = 6755399441055744.0;  // 1.5 * 2^52: adding and subtracting rounds to nearest
  const Lanes4 n = (x * kLog2e + kRound) - kRound;
  const Lanes4 r = (x - n * kLn2Hi) - n * kLn2Lo;
  Lanes4 p = r * (1.0 / 6227020800.0) + 1.0 / 479001600.0;  // 1/13!, 1/12!
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  const Ints4 e = (__builtin_convertvector(n, Ints4) + 1023) << 52;  // 2^n, n in [-1022, 0]
  Lanes4 scale;
  std::memcpy(&scale, &e, sizeof scale);
  const Lanes4 result = p * scale;
  *value = underflow ? Lanes4{0, 0, 0, 0} : result;
}

DGMM_ALWAYS_INLINE void NormaliseBlockImpl(const double* const* logp, int K, Eigen::Index b, double* const* resp,
                                           double* row_max, double* row_sum) {
  Eigen::Index i = 0;
  for (; i + 4 <= b; i += 4) {
    Lanes4 m, v, sum = {0, 0, 0, 0};
    std::memcpy(&m, logp[0] + i, sizeof m);
    for (int k = 1; k < K; ++k) {
      std::memcpy(&v, logp[k] + i, sizeof v);
      m = v > m ? v : m;
    }
    for (int k = 0; k < K; ++k) {
      std::memcpy(&v, logp[k] + i, sizeof v);
      v -= m;
      ExpNonPositive(&v);
      std::memcpy(resp[k] + i, &v, sizeof v);
      sum += v;
    }
    const Lanes4 inverse = 1.0 / sum;
    for (int k = 0; k < K; ++k) {
      std::memcpy(&v, resp[k] + i, sizeof v);
      v *= inverse;
      std::memcpy(resp[k] + i, &v, sizeof v);
    }
    std::memcpy(row_max + i, &m, sizeof m);
    std::memcpy(row_sum + i, &sum, sizeof sum);
  }
  for (; i < b; ++i) {  // the tail, one lane used
    double m = logp[0][i];
    for (int k = 1; k < K; ++k) m = std::max(m, logp[k][i]);
    double sum = 0;
    for (int k = 0; k < K; ++k) {
      Lanes4 v = {logp[k][i] - m, 0, 0, 0};
      ExpNonPositive(&v);
      sum += resp[k][i] = v[0];
    }
    for (int k = 0; k < K; ++k) resp[k][i] /= sum;
    row_max[i] = m;
    row_sum[i] = sum;
  }
}

}  // namespace

DGMM_TARGET_CLONES void NormaliseBlock(const double* const* logp, int K, Eigen::Index b, double* const* resp,
                                       double* row_max, double* row_sum) {
  NormaliseBlockImpl(logp, K, b, resp, row_max, row_sum);
}

DGMM_TARGET_CLONES void SquaredMahalanobisBlock(const double* const* cols, Eigen::Index b, int d,
                                            const double* U,
                             const double* shift, double* m2) {
  switch (d) {
    case 1: return SquaredMahalanobisBlockFixed<1>(cols, b, U, shift, m2);
    case 2: return SquaredMahalanobisBlockFixed<2>(cols, b, U, shift, m2);
    case 3: return SquaredMahalanobisBlockFixed<3>(cols, b, U, shift, m2);
    case 4: return SquaredMahalanobisBlockFixed<4>(cols, b, U, shift, m2);
    case 5: return SquaredMahalanobisBlockFixed<5>(cols, b, U, shift, m2);
    case 6: return SquaredMahalanobisBlockFixed<6>(cols, b, U, shift, m2);
    case 7: return SquaredMahalanobisBlockFixed<7>(cols, b, U, shift, m2);
    case 8: return SquaredMahalanobisBlockFixed<8>(cols, b, U, shift, m2);
    default: assert(false);
  }
}

DGMM_TARGET_CLONES void WeightedMoments(const double* const* cols, Eigen::Index n, int d, const double* r,
                                        const double* shift, double* first, double* second) {
  switch (d) {
    case 1: return WeightedMomentsFixed<1>(cols, n, r, shift, first, second);
    case 2: return WeightedMomentsFixed<2>(cols, n, r, shift, first, second);
    case 3: return WeightedMomentsFixed<3>(cols, n, r, shift, first, second);
    case 4: return WeightedMomentsFixed<4>(cols, n, r, shift, first, second);
    case 5: return WeightedMomentsFixed<5>(cols, n, r, shift, first, second);
    case 6: return WeightedMomentsFixed<6>(cols, n, r, shift, first, second);
    case 7: return WeightedMomentsFixed<7>(cols, n, r, shift, first, second);
    case 8: return WeightedMomentsFixed<8>(cols, n, r, shift, first, second);
    default: assert(false);
  }
}

}  // namespace dgmm::em_internal
