#include "sim/gait_table.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "util/error.h"

namespace dgmm::sim {
namespace {

// Leg indices of one side ordered front to back.
std::vector<int> SideFrontToBack(const std::vector<LegPlace>& legs, int side) {
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(legs.size()); ++i) {
    if (legs[i].side == side) out.push_back(i);
  }
  std::stable_sort(out.begin(), out.end(), [&](int a, int b) { return legs[a].forward_m > legs[b].forward_m; });
  return out;
}

// Phases by (side, position from the front) for a pattern on 2 * per_side legs.
using PhaseTable = std::vector<std::vector<double>>;  // [0] left front..back, [1] right front..back

GaitTiming FromTable(const PhaseTable& table, double duty, const std::vector<LegPlace>& legs,
                     const std::string& pattern, const std::string& source) {
  const std::vector<int> left = SideFrontToBack(legs, 1), right = SideFrontToBack(legs, -1);
  const std::size_t per_side = table[0].size();
  if (legs.size() != 2 * per_side || left.size() != per_side || right.size() != per_side) {
    throw MakeInputError(source, "robot.gait.pattern",
                         pattern + " needs " + std::to_string(2 * per_side) + " legs, " + std::to_string(per_side) +
                             " on each side; the robot has " + std::to_string(left.size()) + " left and " +
                             std::to_string(right.size()) + " right");
  }
  GaitTiming t;
  t.duty = duty;
  t.phase.assign(legs.size(), 0);
  for (std::size_t k = 0; k < per_side; ++k) {
    t.phase[left[k]] = table[0][k];
    t.phase[right[k]] = table[1][k];
  }
  return t;
}

}  // namespace

GaitTiming ResolveGait(const GaitDescription& gait, const std::vector<LegPlace>& legs, const std::string& source) {
  std::string pattern = gait.pattern;
  if (pattern == "auto") {
    if (legs.size() == 4) pattern = "trot";
    else if (legs.size() == 6) pattern = "tripod";
    else if (legs.size() == 8) pattern = "alternating_tetrapod";
    else {
      throw MakeInputError(source, "robot.gait.pattern",
                           "no default gait for " + std::to_string(legs.size()) +
                               " legs: give pattern custom with one phase per leg");
    }
  }
  GaitTiming t;
  if (pattern == "custom") {
    if (gait.phases.size() != legs.size()) {
      throw MakeInputError(source, "robot.gait.phases",
                           "expected " + std::to_string(legs.size()) + " phases, one per leg");
    }
    t.phase = gait.phases;
    t.duty = 0.5;
  } else if (pattern == "trot") {
    t = FromTable({{0.0, 0.5}, {0.5, 0.0}}, 0.5, legs, pattern, source);
  } else if (pattern == "crawl") {  // hind left, front left, hind right, front right
    t = FromTable({{0.25, 0.0}, {0.75, 0.5}}, 0.75, legs, pattern, source);
  } else if (pattern == "tripod") {
    t = FromTable({{0.0, 0.5, 0.0}, {0.5, 0.0, 0.5}}, 0.5, legs, pattern, source);
  } else if (pattern == "tetrapod") {  // three pairs, one swinging at a time, back to front
    t = FromTable({{0.0, 2.0 / 3, 1.0 / 3}, {1.0 / 3, 0.0, 2.0 / 3}}, 2.0 / 3, legs, pattern, source);
  } else if (pattern == "wave") {  // back to front, left side then right
    t = FromTable({{2.0 / 6, 1.0 / 6, 0.0}, {5.0 / 6, 4.0 / 6, 3.0 / 6}}, 5.0 / 6, legs, pattern, source);
    t.side_sequential = true;
  } else {  // alternating_tetrapod
    t = FromTable({{0.0, 0.5, 0.0, 0.5}, {0.5, 0.0, 0.5, 0.0}}, 0.5, legs, pattern, source);
  }
  if (gait.duty_factor > 0) t.duty = gait.duty_factor;
  t.phase_backward = t.phase;
  if (pattern != "custom") {
    for (double& p : t.phase_backward) p = p > 0 ? 1.0 - p : 0.0;
  }
  return t;
}

double LateralShift(const GaitTiming& timing, const std::vector<double>& phase, const std::vector<int>& sides,
                    double lateral) {
  if (!timing.side_sequential || lateral == 0) return 0;
  int first = -1;
  double earliest = 2;
  for (std::size_t i = 0; i < phase.size(); ++i) {
    double lift = phase[i] + timing.duty;
    lift -= std::floor(lift);
    if (lift < earliest) earliest = lift, first = static_cast<int>(i);
  }
  const int leading = lateral > 0 ? 1 : -1;
  return first >= 0 && sides[first] == leading ? 0.5 : 0;
}

Eigen::Vector3d FootOffset(double u, double duty, const Eigen::Vector2d& d, double lift) {
  u -= std::floor(u);
  if (u < duty) {
    const Eigen::Vector2d xy = d * (0.5 - u / duty);
    return Eigen::Vector3d(xy.x(), xy.y(), 0);
  }
  const double s = (u - duty) / (1 - duty);
  const Eigen::Vector2d xy = d * (-0.5 + 0.5 * (1 - std::cos(M_PI * s)));
  return Eigen::Vector3d(xy.x(), xy.y(), lift * std::sin(M_PI * s));
}

double ResolveSway(double sway, double duty) {
  const double kDefaultSway = 0.1;  // of the way to the other feet's centroid (relative to the stance polygon)
  const double kStaticDuty = 0.75;  // duty factor of a crawl: three of four feet down at every instant
  if (sway >= 0) return sway;
  return duty >= kStaticDuty - 1e-9 ? kDefaultSway : 0;
}

std::vector<Eigen::Vector2d> SwayTargets(const std::vector<Eigen::Vector2d>& stance, double share) {
  const int n = static_cast<int>(stance.size());
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& p : stance) sum += p;
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : stance) {
    // centroid of the others minus the centroid of all = (mean - p_i) / (n - 1)
    out.push_back(n > 1 ? Eigen::Vector2d(share * (sum / n - p) / (n - 1)) : Eigen::Vector2d::Zero());
  }
  return out;
}

double SwingWeight(double u, double duty) {
  const double swing = 1 - duty;
  double delta = u - (1 + duty) / 2;  // from mid-swing, wrapped to [-0.5, 0.5)
  delta -= std::floor(delta + 0.5);
  return std::abs(delta) < swing ? 0.5 * (1 + std::cos(M_PI * delta / swing)) : 0;
}

}  // namespace dgmm::sim
