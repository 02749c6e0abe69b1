#include "predict/ground_terrain.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/plane_fit.h"
#include "util/error.h"

namespace dgmm::predict {
namespace {

enum class Sensed { kPitch, kRoll, kFootRelief, kHeightAhead, kGiven };

std::vector<Sensed> SensedDimensions(const MotionModel& model, const std::vector<std::string>& given) {
  std::vector<Sensed> out;
  bool any = false;
  for (const std::string& name : model.terrain_names) {
    if (std::find(given.begin(), given.end(), name) != given.end()) {
      out.push_back(Sensed::kGiven);
      continue;
    }
    any = true;
    if (name == "pitch") out.push_back(Sensed::kPitch);
    else if (name == "roll") out.push_back(Sensed::kRoll);
    else if (name == "foot_relief") out.push_back(Sensed::kFootRelief);
    else if (name == "height_ahead") out.push_back(Sensed::kHeightAhead);
    else throw MakeInputError("model", "terrain", "\"" + name + "\" is not something a ground gives (pitch, roll, foot_relief, height_ahead)");
  }
  if (!any) throw MakeInputError("model", "terrain", "has no terrain dimensions to read off a ground");
  return out;
}

void CheckFootprint(const GroundSurface& ground) {
  if (!ground.height) return;
  const auto& f = ground.footprint_m;
  double area = 0;  // twice the largest triangle: the feet must span a plane
  for (std::size_t i = 0; i < f.size(); ++i)
    for (std::size_t j = i + 1; j < f.size(); ++j)
      for (std::size_t k = j + 1; k < f.size(); ++k) {
        const Eigen::Vector2d u = f[j] - f[i], v = f[k] - f[i];
        area = std::max(area, std::abs(u.x() * v.y() - u.y() * v.x()));
      }
  if (f.size() < 3 || area <= 1e-12) {
    throw MakeInputError("ground", "footprint", "a height field needs at least three feet not on one line");
  }
}

// The ground under the feet at a pose: slope-frame points (x, y, height).
std::vector<Eigen::Vector3d> GroundUnderFeet(const GroundSurface& g, const Eigen::Vector4d& pose) {
  const Eigen::Rotation2Dd yaw(pose[3]);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector2d& foot : g.footprint_m) {
    const Eigen::Vector2d at = pose.head<2>() + yaw * foot;
    points.emplace_back(at.x(), at.y(), g.height(at.x(), at.y()));
  }
  return points;
}

// IMU pitch and roll of a torso parallel to the surface with normal n (slope frame) at heading yaw.
Eigen::Vector2d PitchRoll(double slope_rad, const Eigen::Vector3d& n, double yaw) {
  const Eigen::Vector3d heading(std::cos(yaw), std::sin(yaw), 0);
  const Eigen::Vector3d x = (heading - heading.dot(n) * n).normalized(), y = n.cross(x);
  const Eigen::Vector3d up(std::sin(slope_rad), 0, std::cos(slope_rad));
  const Eigen::Vector3d g(x.dot(up), y.dot(up), n.dot(up));
  return {std::atan2(-g.x(), std::hypot(g.y(), g.z())), std::atan2(g.y(), g.z())};
}

}  // namespace

std::function<Eigen::VectorXd(const Eigen::Vector4d&)> GroundTerrain(const MotionModel& model, const GroundSurface& ground,
                                                                    const std::vector<std::string>& given) {
  const std::vector<Sensed> dims = SensedDimensions(model, given);
  CheckFootprint(ground);
  return [dims, ground](const Eigen::Vector4d& pose) {
    PlaneFit plane;
    if (ground.height) plane = FitPlane(GroundUnderFeet(ground, pose));
    const Eigen::Vector2d pr = PitchRoll(ground.slope_rad, Eigen::Vector3d(-plane.b, -plane.c, 1).normalized(), pose[3]);
    Eigen::VectorXd z(static_cast<int>(dims.size()));
    for (int i = 0; i < z.size(); ++i) {
      switch (dims[i]) {
        case Sensed::kGiven: z[i] = NAN; break;
        case Sensed::kPitch: z[i] = pr[0]; break;
        case Sensed::kRoll: z[i] = pr[1]; break;
        case Sensed::kFootRelief: z[i] = ground.footprint_m.size() < 4 ? 0.0 : plane.rms_residual; break;
        case Sensed::kHeightAhead: {
          if (!ground.height) { z[i] = 0; break; }
          const Eigen::Vector2d here = pose.head<2>();
          const Eigen::Vector2d there = here + ground.reach_m * Eigen::Vector2d(std::cos(pose[3]), std::sin(pose[3]));
          z[i] = ground.height(there.x(), there.y()) - ground.height(here.x(), here.y());
        }
      }
    }
    return z;
  };
}

}  // namespace dgmm::predict
