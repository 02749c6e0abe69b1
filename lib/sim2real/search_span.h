#pragma once
// What a likelihood search (refine.h, stage 4) could not tell apart: the searched points that fit
// the real samples as well as its best, within z standard errors of the best's log-likelihood
// with placements as the independent units (refine_search.h, FitAsWellAsTheBest). Their values
// span more than the bootstrap interval where the data cannot separate the values (a payload's
// mass against its forward position, a friction above what the gait needs to grip).
#include <cmath>

namespace dgmm::sim2real {

struct SearchSpan {
  double lower = NAN, upper = NAN;      // the knob's values (the payload: its masses); NaN: no search
  double x_lower = NAN, x_upper = NAN;  // the payload's forward offsets (m); NaN otherwise
  int points = 0;                       // that fit as well, the best among them
  int searched = 0;                     // scored by the search
  double z = 0;
  bool Searched() const { return points > 0; }
  // Does the span widen the interval [lo, hi] (NaN: none) materially: is their union at least
  // 1.5 times as wide as the interval? (A span a grid step past an interval's ends is noise.)
  bool Beyond(double lo, double hi) const {
    if (!Searched()) return false;
    if (!std::isfinite(lo) || !std::isfinite(hi)) return upper > lower;
    return std::fmax(upper, hi) - std::fmin(lower, lo) >= 1.5 * (hi - lo) && (lower < lo || upper > hi);
  }
};

}  // namespace dgmm::sim2real
