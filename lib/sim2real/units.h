#pragma once
// Rows grouped into the exchangeable units of the tests (placements, episodes, clusters): each
// distinct label becomes a dense id 0 .. count - 1 in order of first appearance, so that
//   unit[i] = id of labels[i].
#include <map>
#include <vector>

namespace dgmm::sim2real {

struct UnitIds {
  std::vector<int> unit;  // per row
  int count = 0;
};

inline UnitIds NumberUnits(const std::vector<int>& labels) {
  UnitIds u;
  std::map<int, int> id;
  u.unit.reserve(labels.size());
  for (int label : labels) u.unit.push_back(id.emplace(label, static_cast<int>(id.size())).first->second);
  u.count = static_cast<int>(id.size());
  return u;
}

}  // namespace dgmm::sim2real
