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

// WeightedScatter for d = D, in blocks of kScatterBlock samples: the block is centred once
// (D columns in L1 cache), then each row a of the triangle accumulates its a + 1 sums over the
// block in registers (4 lanes: one AVX or two SSE2 registers per sum), so no sum is spilled.
constexpr Eigen::Index kScatterBlock = 256;

template <int D>
DGMM_ALWAYS_INLINE void WeightedScatterFixed(const double* const* cols, Eigen::Index n,
                                         const double* r, const double* mean, double* cov) {
  typedef double Lanes __attribute__((vector_size(4 * sizeof(double))));
  alignas(32) double centred[D][kScatterBlock];
  double sums[D][D] = {};
  for (Eigen::Index i0 = 0; i0 < n; i0 += kScatterBlock) {
    const Eigen::Index b = std::min(kScatterBlock, n - i0);
    const Eigen::Index b4 = b & ~Eigen::Index{3};
    for (int a = 0; a < D; ++a) {
      for (Eigen::Index i = 0; i < b; ++i) centred[a][i] = cols[a][i0 + i] - mean[a];
    }
#pragma GCC unroll 8
    for (int a = 0; a < D; ++a) {
      Lanes acc[D];
#pragma GCC unroll 8
      for (int c = 0; c <= a; ++c) acc[c] = Lanes{0, 0, 0, 0};
      for (Eigen::Index i = 0; i < b4; i += 4) {
        Lanes weight, w;
        std::memcpy(&weight, r + i0 + i, sizeof(Lanes));
        std::memcpy(&w, &centred[a][i], sizeof(Lanes));
        w *= weight;
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
    }
  }
  for (int a = 0; a < D; ++a)
    for (int c = 0; c <= a; ++c) cov[a + c * D] += sums[a][c];
}

}  // namespace

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

DGMM_TARGET_CLONES void WeightedScatter(const double* const* cols, Eigen::Index n, int d,
                                    const double* r,
                     const double* mean, double* cov) {
  switch (d) {
    case 1: return WeightedScatterFixed<1>(cols, n, r, mean, cov);
    case 2: return WeightedScatterFixed<2>(cols, n, r, mean, cov);
    case 3: return WeightedScatterFixed<3>(cols, n, r, mean, cov);
    case 4: return WeightedScatterFixed<4>(cols, n, r, mean, cov);
    case 5: return WeightedScatterFixed<5>(cols, n, r, mean, cov);
    case 6: return WeightedScatterFixed<6>(cols, n, r, mean, cov);
    case 7: return WeightedScatterFixed<7>(cols, n, r, mean, cov);
    case 8: return WeightedScatterFixed<8>(cols, n, r, mean, cov);
    default: assert(false);
  }
}

}  // namespace dgmm::em_internal
