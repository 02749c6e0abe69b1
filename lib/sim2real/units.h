#pragma once
// Rows grouped into the exchangeable units of the tests (placements, episodes, clusters): each
// distinct label becomes a dense id 0 .. count - 1 in order of first appearance, so that
//   unit[i] = id of labels[i].
#include <cstddef>
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

// The same with ids in ascending order of label (recording order when the labels are placement ids).
inline UnitIds NumberUnitsAscending(const std::vector<int>& labels) {
  std::map<int, int> id;
  for (int label : labels) id.emplace(label, 0);
  int next = 0;
  for (auto& [label, k] : id) k = next++;
  UnitIds u;
  u.unit.reserve(labels.size());
  for (int label : labels) u.unit.push_back(id[label]);
  u.count = next;
  return u;
}

// The rows of each unit: rows[u] lists, in order, the rows i with unit[i] == u.
inline std::vector<std::vector<int>> RowsOfUnits(const UnitIds& u) {
  std::vector<std::vector<int>> rows(u.count);
  for (std::size_t i = 0; i < u.unit.size(); ++i) rows[u.unit[i]].push_back(static_cast<int>(i));
  return rows;
}

}  // namespace dgmm::sim2real
