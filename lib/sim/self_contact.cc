#include "sim/self_contact.h"

#include <algorithm>

namespace dgmm::sim {

void SelfContacts::Observe(const mjModel* m, const mjData* d) {
  bool any = false;
  std::pair<int, int> last{-1, -1};
  for (int i = 0; i < d->ncon; ++i) {
    const int a = m->geom_bodyid[d->contact[i].geom1], b = m->geom_bodyid[d->contact[i].geom2];
    if (a <= 0 || b <= 0) continue;  // one of them is the world: the ground
    const std::pair<int, int> pair{std::min(a, b), std::max(a, b)};
    if (pair != last) ++pairs_[pair];  // a pair once per step (consecutive contacts of one pair)
    last = pair;
    any = true;
  }
  steps_ += any;
}

std::string SelfContacts::MostFrequentPair(const mjModel* m) const {
  const auto top = std::max_element(pairs_.begin(), pairs_.end(),
                                    [](const auto& x, const auto& y) { return x.second < y.second; });
  if (top == pairs_.end()) return "";
  auto name = [m](int body) {
    const char* n = mj_id2name(m, mjOBJ_BODY, body);
    return n ? std::string(n) : "body " + std::to_string(body);
  };
  return name(top->first.first) + " with " + name(top->first.second);
}

}  // namespace dgmm::sim
