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

// The weighted moments about a shift s, in one pass over the n samples:
//   first[a] += sum_i r[i] (x_ia - s_a),  lower triangle of second (d x d, column-major)
//   += sum_i r[i] (x_i - s)(x_i - s)^T.   1 <= d <= kMaxFixedDim.
void WeightedMoments(const double* const* cols, Eigen::Index n, int d, const double* r,
                     const double* shift, double* first, double* second);

// The E-step's normalisation of one block of b samples and K components, by log-sum-exp:
// resp[k][i] = exp(logp[k][i] - m_i) / s_i with m_i = max_k logp[k][i] (row_max[i]) and
// s_i = sum_k exp(logp[k][i] - m_i) (row_sum[i]); log p(x_i) = m_i + log s_i. logp[k], resp[k]: b values each.
// exp by Cody-Waite reduction to |r| <= ln 2 / 2 and a degree-13 Taylor polynomial (relative error
// under 1e-15; exponents under -708 give 0), four lanes at a time.
void NormaliseBlock(const double* const* logp, int K, Eigen::Index b, double* const* resp, double* row_max,
                    double* row_sum);

}  // namespace dgmm::em_internal
