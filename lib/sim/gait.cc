#include "sim/gait.h"

#include <algorithm>
#include <cmath>

namespace dgmm::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

double WrapAngle(double a) { return std::remainder(a, 2 * kPi); }

// Share of each swing, at its start and at its end, spent with the foot still on the ground so
// both tetrapods carry the robot while the load changes over (less slip on the slope).
constexpr double kPlanted = 0.15;

// Swing progress w in [0, 1] -> progress of the airborne part.
double Airborne(double w) { return std::clamp((w - kPlanted) / (1 - 2 * kPlanted), 0.0, 1.0); }

// Smooth 0 -> 1 over the airborne part of a swing (zero velocity at both ends).
double Ease(double w) { return 0.5 * (1 - std::cos(kPi * Airborne(w))); }

// Foot lift over a swing: 0 while planted, one sine arch while airborne.
double Lift(double w) { return std::sin(kPi * Airborne(w)); }

}  // namespace

Eigen::Vector3d LegForward(const LegGeometry& leg, const LegAngles& q) {
  const double heading = leg.outward_rad + q[0];
  const double a = q[1], g = q[1] + q[2];
  const double r = leg.coxa_out_m + leg.femur_m * std::cos(a) + leg.tibia_m * std::sin(g);
  const double h = leg.coxa_up_m + leg.femur_m * std::sin(a) - leg.tibia_m * std::cos(g);
  return leg.hip_m + Eigen::Vector3d(r * std::cos(heading), r * std::sin(heading), h);
}

LegAngles LegInverse(const LegGeometry& leg, const Eigen::Vector3d& foot_m) {
  const Eigen::Vector3d v = foot_m - leg.hip_m;
  const double yaw = WrapAngle(std::atan2(v.y(), v.x()) - leg.outward_rad);
  const double r = std::hypot(v.x(), v.y()) - leg.coxa_out_m;
  const double h = v.z() - leg.coxa_up_m;
  const double l1 = leg.femur_m, l2 = leg.tibia_m;
  // Two-link arm with absolute angles a (femur) and g - pi/2 (tibia); q = their difference.
  double d = std::hypot(r, h);
  const double kMargin = 1e-6;  // keeps acos away from +-1 at full stretch or fold
  d = std::clamp(d, std::abs(l1 - l2) + kMargin, l1 + l2 - kMargin);
  const double c = std::clamp((d * d - l1 * l1 - l2 * l2) / (2 * l1 * l2), -1.0, 1.0);
  const double q = -std::acos(c);  // knee above the line from hip to foot
  const double direction = std::atan2(h, r);
  const double a = direction - std::atan2(l2 * std::sin(q), l1 + l2 * std::cos(q));
  return {yaw, a, q + kPi / 2};
}

Eigen::Vector3d NominalFoot(const LegGeometry& leg, const GaitConfig& gait) {
  const double r = leg.coxa_out_m + leg.femur_m;
  return {leg.hip_m.x() + r * std::cos(leg.outward_rad), leg.hip_m.y() + r * std::sin(leg.outward_rad),
          -(gait.stance_height_m - leg.foot_radius_m)};
}

bool InTetrapodA(int leg) { return leg == 0 || leg == 2 || leg == 5 || leg == 7; }

Eigen::Vector3d FootTarget(const LegGeometry& leg, int leg_index, const Eigen::Vector3d& command,
                           double t, double duration, const GaitConfig& gait) {
  const Eigen::Vector3d p = NominalFoot(leg, gait);
  if (t <= 0 || t >= duration) return p;
  const Eigen::Vector2d d =
      gait.stride_m * Eigen::Vector2d(command[0], command[1]) +
      gait.turn_rad * command[2] * Eigen::Vector2d(-p.y(), p.x());
  const double period = gait.period_s;
  const int cycles = std::max(1, static_cast<int>(std::lround(duration / period)));
  const int k = std::min(cycles - 1, static_cast<int>(t / period));
  const double s = t / period - k;  // phase in [0, 1)
  double offset = 0, lift = 0;      // offset along d in [-1/2, 1/2]; lift in [0, 1]
  if (InTetrapodA(leg_index)) {
    if (s < 0.25) {
      offset = -0.5 * (s / 0.25);
    } else if (s < 0.75) {
      const double w = (s - 0.25) / 0.5;
      offset = -0.5 + Ease(w);
      lift = Lift(w);
    } else {
      offset = 0.5 - 0.5 * ((s - 0.75) / 0.25);
    }
  } else {
    if (s < 0.25) {
      if (k == 0) {  // first half-swing from the standing pose
        const double w = s / 0.25;
        offset = 0.5 * Ease(w);
        lift = Lift(w);
      } else {  // second half of a swing that began in the previous period
        const double w = 0.5 + 0.5 * (s / 0.25);
        offset = -0.5 + Ease(w);
        lift = Lift(w);
      }
    } else if (s < 0.75) {
      offset = 0.5 - (s - 0.25) / 0.5;
    } else if (k == cycles - 1) {  // last half-swing back to the standing pose
      const double w = (s - 0.75) / 0.25;
      offset = -0.5 + 0.5 * Ease(w);
      lift = Lift(w);
    } else {
      const double w = 0.5 * (s - 0.75) / 0.25;
      offset = -0.5 + Ease(w);
      lift = Lift(w);
    }
  }
  return p + Eigen::Vector3d(offset * d.x(), offset * d.y(), lift * gait.step_height_m);
}

}  // namespace dgmm::sim
