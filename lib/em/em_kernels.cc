#include "em/em_kernels.h"

#include <cassert>
#include <cstring>

namespace dgmm::em_internal {
namespace {

// m2_i = |U^T x_i - shift|^2 for the b samples of a block (cols[a]: column a of the block, U:
// d x d upper triangular, column-major). D fixes d at compile time so that the loops over
// dimensions unroll and the loop over samples vectorises.
template <int D>
void SquaredMahalanobisBlockFixed(const double* const* cols, Eigen::Index b, const double* U,
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

// WeightedScatter for d = D: the d(d+1)/2 sums stay in registers, two samples per SSE2 lane pair.
template <int D>
void WeightedScatterFixed(const double* const* cols, Eigen::Index n, const double* r,
                          const double* mean, double* cov) {
  typedef double Pair __attribute__((vector_size(2 * sizeof(double))));
  constexpr int kSums = D * (D + 1) / 2;
  Pair sums[kSums];
  for (int q = 0; q < kSums; ++q) sums[q] = Pair{0, 0};
  Eigen::Index i = 0;
  for (; i + 2 <= n; i += 2) {
    Pair weight, c[D];
    std::memcpy(&weight, r + i, sizeof(Pair));
    for (int a = 0; a < D; ++a) {
      std::memcpy(&c[a], cols[a] + i, sizeof(Pair));
      c[a] -= mean[a];
    }
    int q = 0;
    for (int a = 0; a < D; ++a) {
      const Pair w = c[a] * weight;
      for (int b = 0; b <= a; ++b) sums[q++] += w * c[b];
    }
  }
  double tail[kSums] = {};
  for (; i < n; ++i) {
    double c[D];
    for (int a = 0; a < D; ++a) c[a] = cols[a][i] - mean[a];
    int q = 0;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b <= a; ++b) tail[q++] += r[i] * c[a] * c[b];
  }
  int q = 0;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b <= a; ++b, ++q) cov[a + b * D] += sums[q][0] + sums[q][1] + tail[q];
}

}  // namespace

void SquaredMahalanobisBlock(const double* const* cols, Eigen::Index b, int d, const double* U,
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

void WeightedScatter(const double* const* cols, Eigen::Index n, int d, const double* r,
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
