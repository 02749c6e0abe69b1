// lib/em/em_kernels.h: the inner loops against plain Eigen arithmetic.
#include "em/em_kernels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace dgmm::em_internal {
namespace {

// Log-sum-exp normalisation of blocks (tails of 1 to 3 samples included), with log-probabilities
// spread over 0 to -800 so that some exponents underflow: responsibilities to 1e-14 relative,
// the row sums to 1e-14, underflowing terms exactly 0.
TEST(EmKernelsTest, NormaliseBlockIsLogSumExp) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> spread(-800.0, 0.0), near(-30.0, 0.0);
  for (int K : {1, 3, 5}) {
    for (Eigen::Index b : {1, 7, 256}) {
      Eigen::ArrayXXd logp(b, K), resp(b, K);
      for (Eigen::Index i = 0; i < b; ++i)
        for (int k = 0; k < K; ++k) logp(i, k) = (i + k) % 3 == 0 ? spread(rng) : near(rng);
      std::vector<const double*> lp(K);
      std::vector<double*> rp(K);
      for (int k = 0; k < K; ++k) lp[k] = &logp(0, k), rp[k] = &resp(0, k);
      Eigen::ArrayXd row_max(b), row_sum(b);
      NormaliseBlock(lp.data(), K, b, rp.data(), row_max.data(), row_sum.data());
      for (Eigen::Index i = 0; i < b; ++i) {
        const double m = logp.row(i).maxCoeff();
        const Eigen::ArrayXd e = (logp.row(i) - m).exp().transpose();
        EXPECT_DOUBLE_EQ(row_max(i), m);
        EXPECT_NEAR(row_sum(i) / e.sum(), 1.0, 1e-14);
        for (int k = 0; k < K; ++k) {
          const double want = e(k) / e.sum();
          if (logp(i, k) - m < -708) EXPECT_EQ(resp(i, k), 0.0);
          else EXPECT_NEAR(resp(i, k), want, 1e-14 * want + 1e-300) << K << " " << b << " " << logp(i, k) - m;
        }
      }
    }
  }
}

}  // namespace
}  // namespace dgmm::em_internal
