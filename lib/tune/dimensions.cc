#include "tune/dimensions.h"

#include <algorithm>

#include "util/error.h"

namespace dgmm {
namespace {

// Column indices of `wanted` in `names` (all columns when wanted is empty).
std::vector<int> Columns(const std::vector<std::string>& names,
                         const std::vector<std::string>& wanted, const char* field) {
  std::vector<int> columns;
  if (wanted.empty()) {
    for (int i = 0; i < static_cast<int>(names.size()); ++i) columns.push_back(i);
    return columns;
  }
  for (const std::string& name : wanted) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw MakeInputError("", field, "unknown dimension '" + name + "' (have: " + known + ")");
    }
    columns.push_back(static_cast<int>(it - names.begin()));
  }
  return columns;
}

template <typename Names>
Names Pick(const Names& names, const std::vector<int>& columns) {
  Names out;
  for (int c : columns) {
    if (c < static_cast<int>(names.size())) out.push_back(names[c]);
  }
  return out;
}

}  // namespace

SampleSet SelectDimensions(const SampleSet& set, const std::vector<std::string>& pose_names,
                           const std::vector<std::string>& terrain_names) {
  const std::vector<int> xc = Columns(set.x_names, pose_names, "pose dimensions");
  const std::vector<int> zc = Columns(set.z_names, terrain_names, "terrain dimensions");
  SampleSet out = set;
  out.x = set.x(Eigen::all, xc);
  out.z = set.z(Eigen::all, zc);
  out.x_names = Pick(set.x_names, xc);
  out.x_units = Pick(set.x_units, xc);
  out.z_names = Pick(set.z_names, zc);
  out.z_units = Pick(set.z_units, zc);
  if (!set.transform.empty()) {
    std::vector<int> yc = xc;
    for (int c : zc) yc.push_back(set.pose_dim() + c);
    out.transform.offset = set.transform.offset(yc).eval();
    out.transform.scale = set.transform.scale(yc).eval();
  }
  return out;
}

}  // namespace dgmm
