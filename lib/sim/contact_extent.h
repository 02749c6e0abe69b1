#pragma once
// Internal to dgmm_sim (includes MuJoCo): where a geom meets the ground, for measuring feet (the
// leg binding of legged_robot.h and the drafting of robot_draft.h).
#include <mujoco/mujoco.h>

namespace dgmm::sim {

// How far geom g reaches below its centre along world z in `data` (a foot's contact extent):
// exact for spheres, capsules, cylinders, boxes and ellipsoids, a mesh's lowest vertex, the
// bounding sphere otherwise.
double ExtentBelow(const mjModel* model, const mjData* data, int g);

// Can geom g touch geom f? MuJoCo's filter (either's contype meets the other's conaffinity) or an
// explicit <pair> of the two.
bool CanTouch(const mjModel* model, int g, int f);

}  // namespace dgmm::sim
