#pragma once
// Internal to dgmm_sim: the robot touching itself. A contact between two geoms whose bodies are
// both the robot's (not the world, which holds the floor and the height field; MuJoCo already skips
// parent-child pairs) is a leg striking another leg or the body: physics the simulation keeps, but
// usually a sign that the gait's steps overlap or the stance is too narrow for this robot. The
// protocol counts the executions with any and warns, naming the pair met most often.
#include <map>
#include <string>
#include <utility>

#include <mujoco/mujoco.h>

namespace dgmm::sim {

class SelfContacts {
 public:
  // Counts this step's contacts between two robot bodies (after mj_step).
  void Observe(const mjModel* m, const mjData* d);
  // Steps with at least one such contact, since construction.
  long long steps() const { return steps_; }
  // "<body> with <body>" of the pair in contact for the most steps; empty when none.
  std::string MostFrequentPair(const mjModel* m) const;

 private:
  long long steps_ = 0;
  std::map<std::pair<int, int>, long long> pairs_;  // body ids (smaller first) -> steps
};

}  // namespace dgmm::sim
