#pragma once
// Internal to dgmm_sim2real: printf-style formatting of up to three numbers for the sentences of
// the conclusion and the verdict (one definition for pipeline.cc, knob_analysis.cc, verdict.cc).
#include <cstdio>
#include <string>

namespace dgmm::sim2real {

// snprintf(f, a, b, c) into a string of at most 399 characters.
inline std::string Fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace dgmm::sim2real
