#include "app/wiring/ground_surface.h"

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "sim/simulator.h"
#include "sim/terrain.h"

namespace dgmm::app {

predict::GroundSurface GroundSurfaceOf(const sim::SimConfig& config) {
  predict::GroundSurface ground;
  ground.slope_rad = config.slope_deg * M_PI / 180;
  if (!config.terrain) return ground;
  auto field = std::make_shared<const sim::HeightField>(sim::HeightField::Generate(*config.terrain));
  ground.height = [field](double x, double y) { return field->At(x, y); };
  sim::SimConfig flat = config;  // the footprint: stand on level, flat ground
  flat.terrain.reset();
  flat.slope_deg = 0;
  sim::Simulator sim(flat);
  sim.Place(0, 0, 0);
  const sim::Pose torso = sim.TorsoPose();
  const double yaw = std::atan2(torso.rotation(1, 0), torso.rotation(0, 0));
  const Eigen::Rotation2Dd to_robot(-yaw);
  for (const Eigen::Vector3d& foot : sim.FootPositions()) {
    ground.footprint_m.push_back(to_robot * (foot - torso.position_m).head<2>());
  }
  ground.reach_m = sim.leg_reach_m();
  return ground;
}

}  // namespace dgmm::app
