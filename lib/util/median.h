#pragma once
// The median of a sample, as the pipeline uses it (log import, the sim set's coverage): the upper
// middle for an even count, 0 for none. O(n) by nth_element on a copy.
#include <algorithm>
#include <vector>

namespace dgmm {

inline double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace dgmm
