#include "render/round_ticks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dgmm {

std::vector<Tick> RoundTicks(double lo, double hi, int max_ticks) {
  std::vector<Tick> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double raw = (hi - lo) / std::max(2, max_ticks);
  int e = static_cast<int>(std::floor(std::log10(raw)));
  double m = 10;
  for (double candidate : {1.0, 2.0, 2.5, 5.0}) {
    if (candidate * std::pow(10.0, e) >= raw) {
      m = candidate;
      break;
    }
  }
  if (m == 10) m = 1, ++e;
  const double step = m * std::pow(10.0, e);
  const int decimals = std::max(0, -e + (m == 2.5 ? 1 : 0));
  const double first = std::ceil(lo / step - 1e-9);
  for (int i = 0;; ++i) {
    const double t = (first + i) * step;
    if (t > hi + 1e-9 * step) break;
    const double v = std::abs(t) < 1e-12 * step ? 0.0 : t;
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, v);
    ticks.push_back({v, text});
  }
  return ticks;
}

}  // namespace dgmm
