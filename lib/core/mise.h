#pragma once
// Integrated squared difference of two Gaussian mixtures in closed form. With normalised weights
// a_i = w_i / sum w and the identity  int N(x; m, A) N(x; n, B) dx = N(m; n, A + B),
//   ISE(p, q) = int (p - q)^2 dx = sum_ij a_i a_j N(mu_i; mu_j, S_i + S_j)
//             - 2 sum_ij a_i b_j N(mu_i; nu_j, S_i + T_j) + sum_ij b_i b_j N(nu_i; nu_j, T_i + T_j),
// exact in any dimension. The paper's MISE is the mean of this over repeated fits.
#include "core/mixture.h"

namespace dgmm {

// log int p(x) q(x) dx = log sum_ij a_i b_j N(mu_i; nu_j, S_i + T_j) by log-sum-exp;
// -infinity when either mixture is empty. p.dim() == q.dim() (asserted).
double LogOverlapIntegral(const Mixture& p, const Mixture& q);

// The three terms of the ISE and their combination; all >= 0 except possibly tiny rounding.
struct IseTerms {
  double pp = 0;   // int p^2
  double pq = 0;   // int p q
  double qq = 0;   // int q^2
  double ise = 0;  // pp - 2 pq + qq, clamped at 0 (it is >= 0 in exact arithmetic)
};
IseTerms IntegratedSquaredErrorTerms(const Mixture& p, const Mixture& q);

// int (p(x) - q(x))^2 dx (see above); 0 for identical mixtures, symmetric in p and q.
double IntegratedSquaredError(const Mixture& p, const Mixture& q);

}  // namespace dgmm
