#pragma once
// Axis ticks at round values, for the heat maps' plot axes (no VTK here).
#include <string>
#include <vector>

namespace dgmm {

// One tick: its value and its label.
struct Tick {
  double value = 0;
  std::string label;
};

// Ticks inside [lo, hi] at multiples of step = m * 10^e, m in {1, 2, 2.5, 5}, the smallest such
// step >= (hi - lo) / max(2, max_ticks); labels carry just the decimals the step needs
// (max(0, -e), one more for m = 2.5 below 10), and 0 is never "-0". Empty unless lo < hi, both
// finite.
std::vector<Tick> RoundTicks(double lo, double hi, int max_ticks);

}  // namespace dgmm
