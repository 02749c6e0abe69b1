#pragma once
// The warnings dgmm gave when it made a sample set (dgmm simulate: a torso that started tilted,
// legs touching each other, a config at odds with the robot; dgmm import-log: windows of unequal
// length, continuous commands without bins), kept in the set's metadata under
// kSetWarningsKey, one per line, so the analyses that read the set can repeat them.
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm {

inline constexpr char kSetWarningsKey[] = "recording_warnings";

// Replaces the set's kept warnings (none: the key is removed).
void KeepWarnings(const std::vector<std::string>& warnings, SampleSet* set);
// The set's kept warnings in order, empty lines skipped; none for a set without them.
std::vector<std::string> KeptWarnings(const SampleSet& set);

}  // namespace dgmm
