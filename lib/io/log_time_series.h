#pragma once
// Time series of a log stream (io/log_import.h): interpolation at any time (linear, angles
// unwrapped to shortest arcs), runs without logging gaps, and the pose change between two times
// in the body frame at the first.
#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "util/median.h"

namespace dgmm {

using Interval = std::pair<double, double>;  // [begin, end] in seconds

// A parsed numeric stream: strictly increasing times (s) and one vector per column (SI units).
struct Series {
  std::string path;
  std::vector<double> t;
  std::vector<std::vector<double>> values;  // columns x rows
};

// Replaces an angle series by its continuous version: each step is the shortest arc.
void Unwrap(std::vector<double>* a);

// Index i with t[i] <= time <= t[i+1] and the fraction between them (clamped to [t0, tn]);
// t has >= 2 increasing values.
std::pair<size_t, double> Bracket(const std::vector<double>& t, double time);

// v at a bracket: v[i] + f (v[i+1] - v[i]).
double Lerp(const std::vector<double>& v, std::pair<size_t, double> b);

// Median of t[i] - t[i-1].
double MedianInterval(const std::vector<double>& t);

// Runs of the stream with no pause longer than gap_s, as [first, last] times.
std::vector<Interval> Runs(const std::vector<double>& t, double gap_s);

// The intersections of two sorted lists of disjoint intervals (empty ones dropped).
std::vector<Interval> Intersect(const std::vector<Interval>& a, const std::vector<Interval>& b);

// The pose change from t0 to t1 of a pose series (columns x, y, yaw, or x, y, z, roll, pitch, yaw
// with R = Rz(yaw) Ry(pitch) Rx(roll), angles unwrapped) in the body frame at t0:
//   planar: (dx, dy, dyaw), (dx, dy) = R(yaw0)^T (p1 - p0);
//   6-DoF: (R0^T (p1 - p0), ZYX angles of R0^T R1), orientations interpolated by slerp.
Eigen::VectorXd BodyFramePoseChange(const Series& pose, double t0, double t1);

}  // namespace dgmm
