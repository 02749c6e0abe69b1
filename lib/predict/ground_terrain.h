#pragma once
// The terrain a robot senses where it stands, read off a ground described as data: a plane tilted
// by the slope, optionally with a height field over it (the simulator's `terrain` block), so that
// `Predict` can condition each trajectory on the ground under it. The torso is taken parallel to
// the least-squares plane through the ground under its feet:
//   n = normalise(-b, -c, 1) for that plane h = a + b x + c y (slope frame), body x = the heading
//   projected onto it; up (slope frame) = (sin slope, 0, cos slope); pitch, roll from up in the body
//   frame as the IMU reads them (lib/sim/pose.h).
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/motion_model.h"

namespace dgmm::predict {

struct GroundSurface {
  double slope_rad = 0;  // the plane, tilted about the world y axis (uphill = +x)
  // Height (m) along the slope normal at (x, y) of the slope frame; empty: the plane alone.
  std::function<double(double x_m, double y_m)> height;
  // Where the feet stand relative to the torso, robot frame (x forward, y left; m). Needed with a
  // height field (at least three feet, not on a line).
  std::vector<Eigen::Vector2d> footprint_m;
  double reach_m = 0;  // leg reach (m): "height_ahead" looks this far along the heading
};

// The model's terrain at a pose (x, y, z, yaw; yaw 0 = facing uphill), by the names the simulator
// records: "pitch" and "roll" (rad, nose down and left side up > 0), "foot_relief" (m, sd of the
// ground under the feet about its plane) and "height_ahead" (m, the ground one reach ahead minus
// under the torso). Dimensions named in `given` (continuous command values each step supplies)
// are left NaN. InputError naming the part for other names or a footprint that cannot carry a
// height field.
std::function<Eigen::VectorXd(const Eigen::Vector4d& pose)> GroundTerrain(const MotionModel& model,
                                                                           const GroundSurface& ground,
                                                                           const std::vector<std::string>& given = {});

}  // namespace dgmm::predict
