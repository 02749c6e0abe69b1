#include "sim/gait_table.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

// The wave on any number of legs: one foot in the air at a time, each side's legs from back to
// front, the left side first; the j-th leg of that sequence at phase j / N, duty (N - 1) / N.
GaitTiming Wave(const std::vector<LegPlace>& legs, const std::string& source) {
  if (legs.size() < 3) throw MakeInputError(source, "robot.gait.pattern", "wave needs at least 3 legs");
  std::vector<int> order = SideFrontToBack(legs, 1), right = SideFrontToBack(legs, -1);
  std::reverse(order.begin(), order.end());
  order.insert(order.end(), right.rbegin(), right.rend());
  const double n = static_cast<double>(legs.size());
  GaitTiming t;
  t.duty = (n - 1) / n;
  t.phase.assign(legs.size(), 0);
  for (std::size_t j = 0; j < order.size(); ++j) t.phase[order[j]] = static_cast<double>(j) / n;
  t.side_sequential = true;
  return t;
}

// Neighbours along a side and across in opposite halves of the cycle, per_side legs a side: the
// trot, tripod and alternating tetrapod for 2, 3 and 4.
PhaseTable AlternatingTable(std::size_t per_side) {
  PhaseTable table(2, std::vector<double>(per_side));
  for (std::size_t k = 0; k < per_side; ++k) table[0][k] = 0.5 * (k % 2), table[1][k] = 0.5 * ((k + 1) % 2);
  return table;
}

// The alternating pattern on any equal number of legs a side, 2 or more.
GaitTiming Alternating(const std::vector<LegPlace>& legs, const std::string& source) {
  const std::size_t left = SideFrontToBack(legs, 1).size(), right = legs.size() - left;
  if (left != right || left < 2) {
    throw MakeInputError(source, "robot.gait.pattern",
                         "alternating needs the same number of legs on each side, at least 2; the robot has " +
                             std::to_string(left) + " left and " + std::to_string(right) + " right");
  }
  return FromTable(AlternatingTable(left), 0.5, legs, "alternating", source);
}

// The pattern `auto` stands for: the alternating pattern on equal sides (the trot, tripod and
// alternating tetrapod on 4, 6 and 8 legs), else the wave from 4 legs on.
std::string AutoPattern(const std::vector<LegPlace>& legs, const std::string& source) {
  const std::size_t left = SideFrontToBack(legs, 1).size(), right = legs.size() - left;
  if (left == right && left >= 2) return "alternating";
  if (legs.size() >= 4) return "wave";
  throw MakeInputError(source, "robot.gait.pattern",
                       "no default gait for " + std::to_string(legs.size()) +
                           " legs: give pattern custom with one phase per leg, or a replay controller");
}

}  // namespace

GaitTiming ResolveGait(const GaitDescription& gait, const std::vector<LegPlace>& legs, const std::string& source) {
  const std::string pattern = gait.pattern == "auto" ? AutoPattern(legs, source) : gait.pattern;
  GaitTiming t;
  if (pattern == "custom") {
    if (gait.phases.size() != legs.size()) {
      throw MakeInputError(source, "robot.gait.phases",
                           "expected " + std::to_string(legs.size()) + " phases, one per leg");
    }
    t.phase = gait.phases;
    t.duty = 0.5;
  } else if (pattern == "trot") {
    t = FromTable(AlternatingTable(2), 0.5, legs, pattern, source);
  } else if (pattern == "crawl") {  // hind left, front left, hind right, front right
    t = FromTable({{0.25, 0.0}, {0.75, 0.5}}, 0.75, legs, pattern, source);
  } else if (pattern == "tripod") {
    t = FromTable(AlternatingTable(3), 0.5, legs, pattern, source);
  } else if (pattern == "tetrapod") {  // three pairs, one swinging at a time, back to front
    t = FromTable({{0.0, 2.0 / 3, 1.0 / 3}, {1.0 / 3, 0.0, 2.0 / 3}}, 2.0 / 3, legs, pattern, source);
  } else if (pattern == "wave") {
    t = Wave(legs, source);
  } else if (pattern == "alternating") {
    t = Alternating(legs, source);
  } else {  // alternating_tetrapod
    t = FromTable(AlternatingTable(4), 0.5, legs, pattern, source);
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

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Convex hull of the points, counter-clockwise (Andrew's monotone chain).
std::vector<Eigen::Vector2d> Hull(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return p;
  std::sort(p.begin(), p.end(), [](const auto& a, const auto& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (int pass = 0; pass < 2; ++pass, std::reverse(p.begin(), p.end())) {
    const std::size_t start = k;
    for (const auto& q : p) {
      while (k >= start + 2 && Cross(h[k - 1] - h[k - 2], q - h[k - 2]) <= 0) --k;
      h[k++] = q;
    }
    --k;  // the last point starts the other chain
  }
  h.resize(k);
  return h;
}

// Signed distance from c to the edge of the convex polygon (counter-clockwise): > 0 inside.
double Margin(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& c) {
  if (hull.size() < 3) return 0;
  double m = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    m = std::min(m, Cross(e, c - hull[i]) / e.norm());  // distance left of the edge
  }
  return m;
}

}  // namespace

std::vector<Eigen::Vector2d> SwayTargets(const std::vector<Eigen::Vector2d>& stance, double share) {
  const double kCalmMargin = 0.25;  // margin (of the lifted foot's distance from the centre) needing no sway
  const int n = static_cast<int>(stance.size());
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& p : stance) sum += p;
  const Eigen::Vector2d centre = sum / std::max(n, 1);
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < n; ++i) {
    std::vector<Eigen::Vector2d> others = stance;
    others.erase(others.begin() + i);
    const double reach = (stance[i] - centre).norm();
    // need: 1 with the centre on the edge of the others' hull, 0 from a margin of kCalmMargin x reach
    const double need = std::clamp(1 - Margin(Hull(others), centre) / (kCalmMargin * reach + 1e-12), 0.0, 1.0);
    // centroid of the others minus the centroid of all = (centre - p_i) / (n - 1)
    out.push_back(n > 1 ? Eigen::Vector2d(need * share * (centre - stance[i]) / (n - 1)) : Eigen::Vector2d::Zero());
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
