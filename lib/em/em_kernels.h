#pragma once
// Inner loops of the EM reference for d <= kMaxFixedDim, compiled once per fixed d so that the
// loops over dimensions unroll and the loops over samples vectorise (GCC/Clang vector types).
// Internal to lib/em; X is n x d column-major, cols[a] points at column a.
#include <Eigen/Core>

namespace dgmm::em_internal {

// Largest d with a fixed-size kernel; larger d use the generic Eigen code in em.cc.
constexpr int kMaxFixedDim = 8;

// m2[i] = |U^T x_i - shift|^2 for the b samples x_i = (cols[0][i], ..., cols[d-1][i]); U is
// d x d upper triangular (column-major), shift = U^T mu. 1 <= d <= kMaxFixedDim.
void SquaredMahalanobisBlock(const double* const* cols, Eigen::Index b, int d, const double* U,
                             const double* shift, double* m2);

// Lower triangle of cov (d x d, column-major) += sum_i r[i] (x_i - mean)(x_i - mean)^T over the
// n samples. 1 <= d <= kMaxFixedDim.
void WeightedScatter(const double* const* cols, Eigen::Index n, int d, const double* r,
                     const double* mean, double* cov);

}  // namespace dgmm::em_internal
