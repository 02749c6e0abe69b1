#ifndef DGMM_CORE_LOG_SUM_EXP_H_
#define DGMM_CORE_LOG_SUM_EXP_H_

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>

namespace dgmm {

// log sum_i exp(v_i) = m + log sum_i exp(v_i - m), m = max_i v_i; -inf for an empty or all -inf
// input, +inf if any v_i is +inf, NaN if any is NaN. term(i) gives v_i and is called twice per i
// (max, then sum), so a cheap term needs no buffer.
template <typename Term>
double LogSumExpOf(int n, const Term& term) {
  double m = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    const double v = term(i);
    if (std::isnan(v)) return v;
    m = std::max(m, v);
  }
  if (!std::isfinite(m)) return m;
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += std::exp(term(i) - m);
  return m + std::log(s);
}

inline double LogSumExp(const double* v, int n) {
  return LogSumExpOf(n, [v](int i) { return v[i]; });
}

inline double LogSumExp(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return LogSumExp(v.data(), static_cast<int>(v.size()));
}

}  // namespace dgmm

#endif  // DGMM_CORE_LOG_SUM_EXP_H_
