#include "io/log_time_series.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace dgmm {
namespace {

// Rz(yaw) Ry(pitch) Rx(roll) as a quaternion.
Eigen::Quaterniond FromRpy(double roll, double pitch, double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}

// <roll, pitch, yaw> of R = Rz(yaw) Ry(pitch) Rx(roll), pitch in [-pi/2, pi/2].
Eigen::Vector3d ToRpy(const Eigen::Matrix3d& r) {
  return {std::atan2(r(2, 1), r(2, 2)), std::asin(std::clamp(-r(2, 0), -1.0, 1.0)),
          std::atan2(r(1, 0), r(0, 0))};
}

}  // namespace

// Replaces an angle series by its continuous version: each step is the shortest arc.
void Unwrap(std::vector<double>* a) {
  for (size_t i = 1; i < a->size(); ++i) {
    const double step = std::remainder((*a)[i] - (*a)[i - 1], 2 * std::numbers::pi);
    (*a)[i] = (*a)[i - 1] + step;
  }
}

// Index i with t[i] <= time <= t[i+1] and the fraction between them (clamped to [t0, tn]).
std::pair<size_t, double> Bracket(const std::vector<double>& t, double time) {
  size_t i = std::upper_bound(t.begin(), t.end(), time) - t.begin();
  i = std::clamp<size_t>(i == 0 ? 0 : i - 1, 0, t.size() - 2);
  const double f = std::clamp((time - t[i]) / (t[i + 1] - t[i]), 0.0, 1.0);
  return {i, f};
}

double Lerp(const std::vector<double>& v, std::pair<size_t, double> b) {
  return v[b.first] + b.second * (v[b.first + 1] - v[b.first]);
}

double MedianInterval(const std::vector<double>& t) {
  std::vector<double> d;
  for (size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
  return Median(d);
}

// Runs of the stream with no pause longer than gap_s.
std::vector<Interval> Runs(const std::vector<double>& t, double gap_s) {
  std::vector<Interval> runs;
  size_t start = 0;
  for (size_t i = 1; i <= t.size(); ++i) {
    if (i == t.size() || t[i] - t[i - 1] > gap_s) {
      if (i - 1 > start) runs.push_back({t[start], t[i - 1]});
      start = i;
    }
  }
  return runs;
}

std::vector<Interval> Intersect(const std::vector<Interval>& a, const std::vector<Interval>& b) {
  std::vector<Interval> out;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double lo = std::max(a[i].first, b[j].first), hi = std::min(a[i].second, b[j].second);
    if (hi > lo) out.push_back({lo, hi});
    (a[i].second < b[j].second) ? ++i : ++j;
  }
  return out;
}

Eigen::VectorXd BodyFramePoseChange(const Series& pose, double t0, double t1) {
  const auto b0 = Bracket(pose.t, t0), b1 = Bracket(pose.t, t1);
  if (pose.values.size() == 6) {
    auto at = [&](std::pair<size_t, double> b) {
      return Eigen::Vector3d(Lerp(pose.values[0], b), Lerp(pose.values[1], b),
                             Lerp(pose.values[2], b));
    };
    auto rotation = [&](std::pair<size_t, double> b) {
      auto q = [&](size_t i) {
        return FromRpy(pose.values[3][i], pose.values[4][i], pose.values[5][i]);
      };
      return q(b.first).slerp(b.second, q(b.first + 1));  // shortest arc
    };
    const Eigen::Quaterniond q0 = rotation(b0), q1 = rotation(b1);
    Eigen::VectorXd x(6);
    x << q0.conjugate() * (at(b1) - at(b0)), ToRpy((q0.conjugate() * q1).toRotationMatrix());
    return x;
  }
  const double yaw0 = Lerp(pose.values[2], b0);
  const double dx = Lerp(pose.values[0], b1) - Lerp(pose.values[0], b0);
  const double dy = Lerp(pose.values[1], b1) - Lerp(pose.values[1], b0);
  Eigen::VectorXd x(3);
  x << std::cos(yaw0) * dx + std::sin(yaw0) * dy, -std::sin(yaw0) * dx + std::cos(yaw0) * dy,
      Lerp(pose.values[2], b1) - yaw0;
  return x;
}

}  // namespace dgmm
