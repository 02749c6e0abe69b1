#include "core/set_warnings.h"

#include <sstream>

namespace dgmm {

void KeepWarnings(const std::vector<std::string>& warnings, SampleSet* set) {
  std::string lines;
  for (const std::string& w : warnings) lines += (lines.empty() ? "" : "\n") + w;
  if (lines.empty()) {
    set->metadata.erase(kSetWarningsKey);
  } else {
    set->metadata[kSetWarningsKey] = lines;
  }
}

std::vector<std::string> KeptWarnings(const SampleSet& set) {
  std::vector<std::string> warnings;
  const auto it = set.metadata.find(kSetWarningsKey);
  if (it == set.metadata.end()) return warnings;
  std::istringstream lines(it->second);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) warnings.push_back(line);
  }
  return warnings;
}

}  // namespace dgmm
