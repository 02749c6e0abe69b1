#ifndef DGMM_CORE_LOG_SUM_EXP_H_
#define DGMM_CORE_LOG_SUM_EXP_H_

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>

namespace dgmm {

// log sum_i exp(v_i) = m + log sum_i exp(v_i - m), m = max_i v_i; -inf for an empty or all -inf
// input, +inf if any v_i is +inf, NaN if any is NaN.
inline double LogSumExp(const double* v, int n) {
  double m = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    if (std::isnan(v[i])) return v[i];
    m = std::max(m, v[i]);
  }
  if (!std::isfinite(m)) return m;
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += std::exp(v[i] - m);
  return m + std::log(s);
}

inline double LogSumExp(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return LogSumExp(v.data(), static_cast<int>(v.size()));
}

}  // namespace dgmm

#endif  // DGMM_CORE_LOG_SUM_EXP_H_
