#pragma once
// Internal to dgmm_sim2real: printf-style formatting of up to three numbers for the sentences of
// the conclusion and the verdict and lists of words.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace dgmm::sim2real {

// snprintf(f, a, b, c) into a string of at most 399 characters.
inline std::string Fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// "a", "a and b", "a, b and c".
inline std::string JoinWords(const std::vector<std::string>& words) {
  std::string out;
  for (size_t j = 0; j < words.size(); ++j) out += (j == 0 ? "" : j + 1 == words.size() ? " and " : ", ") + words[j];
  return out;
}

// Appends s to the list unless it is there already.
inline void AddUnique(std::vector<std::string>* v, const std::string& s) {
  if (std::find(v->begin(), v->end(), s) == v->end()) v->push_back(s);
}

}  // namespace dgmm::sim2real
