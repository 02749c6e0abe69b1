#pragma once
// Shared helpers for the core tests: random SPD matrices and reusable invariant checks.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "core/dgmm.h"
#include "core/mixture.h"

namespace dgmm::testing {

// A random symmetric positive definite d x d matrix A A^T + 0.5 I.
inline Eigen::MatrixXd RandomSpd(int d, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(d, d);
  for (int i = 0; i < a.size(); ++i) a.data()[i] = normal(rng);
  return a * a.transpose() / d + 0.5 * Eigen::MatrixXd::Identity(d, d);
}

inline Eigen::VectorXd RandomVector(int d, std::mt19937_64& rng, double scale = 1.0) {
  std::normal_distribution<double> normal(0.0, scale);
  Eigen::VectorXd v(d);
  for (int i = 0; i < d; ++i) v[i] = normal(rng);
  return v;
}

// Every component symmetric positive definite with a consistent Cholesky factor; every weight
// positive and finite.
inline void ExpectMixtureInvariants(const Mixture& m) {
  for (int i = 0; i < m.size(); ++i) {
    SCOPED_TRACE("component " + std::to_string(i));
    const Gaussian& g = m.component(i);
    EXPECT_GT(m.weight(i), 0.0);
    EXPECT_TRUE(std::isfinite(m.weight(i)));
    EXPECT_EQ(g.dim(), m.dim());
    EXPECT_TRUE(g.mean().allFinite());
    EXPECT_EQ(g.covariance(), g.covariance().transpose());
    EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(g.covariance()).info(), Eigen::Success);
    const Eigen::MatrixXd& l = g.cholesky_l();
    // Reconstruction error of L L^T relative to the covariance's size (round-off only).
    EXPECT_LE((l * l.transpose() - g.covariance()).norm(), 1e-10 * (1 + g.covariance().norm()));
  }
}

// The DGMM invariants of the paper: weights are sample counts summing to n, stats and mixture
// agree, and the mixture invariants hold.
inline void ExpectDgmmInvariants(const Dgmm& model) {
  const Mixture& m = model.mixture();
  ASSERT_EQ(static_cast<int>(model.stats().size()), m.size());
  double total = 0;
  for (int i = 0; i < m.size(); ++i) {
    EXPECT_EQ(m.weight(i), static_cast<double>(model.stats()[i].count));
    EXPECT_EQ(m.component(i).mean(), model.stats()[i].mean);
    total += m.weight(i);
  }
  EXPECT_EQ(total, static_cast<double>(model.num_samples()));
  ExpectMixtureInvariants(m);
}

}  // namespace dgmm::testing
