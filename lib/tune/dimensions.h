#pragma once
// Choosing which pose and terrain dimensions a cross-validation looks at, by name.
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm {

// The set with x restricted to the named pose dimensions and z to the named terrain dimensions
// (in the order given; an empty list keeps all of that kind). The standardisation transform, if
// any, is restricted alike. Throws InputError naming an unknown dimension and listing the known.
SampleSet SelectDimensions(const SampleSet& set, const std::vector<std::string>& pose_names,
                           const std::vector<std::string>& terrain_names);

}  // namespace dgmm
