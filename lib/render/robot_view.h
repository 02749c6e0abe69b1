#pragma once
// 3-D pictures of a simulated robot from plain geometric primitives (render never sees MuJoCo):
// each scene is a list of boxes, spheres, capsules, cylinders and planes; several scenes render
// side by side into one PNG strip. Offscreen VTK; needs an X display (render/display.h).
#include <Eigen/Core>
#include <string>
#include <vector>

namespace dgmm {

// One solid in world coordinates. Sizes follow MuJoCo's geom_size: box half-extents (x, y, z);
// sphere radius (size[0]); capsule/cylinder radius and half-length along local z (size[0],
// size[1]); plane half-extents x, y (size[0], size[1]) drawn as a finite tile; a height field:
// `grid` x `grid` heights (row-major, row = local y) spaced `spacing` apart, centred on position.
struct ScenePrimitive {
  enum class Type { kPlane, kSphere, kCapsule, kCylinder, kBox, kHeightField };
  Type type = Type::kBox;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // local -> world
  Eigen::Vector4d rgba = Eigen::Vector4d::Ones();
  int grid = 0;           // kHeightField only
  double spacing = 0;
  std::vector<float> heights;
};

// A pinhole camera looking from `position` at `focal_point`.
struct SceneCamera {
  Eigen::Vector3d position{2, -2, 1.5};
  Eigen::Vector3d focal_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d view_up = Eigen::Vector3d::UnitZ();
  double view_angle_deg = 30;
};

struct SceneView {
  std::vector<ScenePrimitive> primitives;
  SceneCamera camera;
  std::string caption;  // drawn in the top-left corner when non-empty
};

struct SceneStripOptions {
  int panel_width = 480, panel_height = 360;
  Eigen::Vector3d background{1, 1, 1};
  // Empty when drawable; otherwise what is wrong.
  std::string Validate() const;
};

// Renders the scenes left to right into one PNG (width = panels * panel_width). Throws
// std::runtime_error without a display, InputError for no scenes, non-finite geometry or an
// unwritable path.
void RenderSceneStrip(const std::vector<SceneView>& scenes, const SceneStripOptions& options,
                      const std::string& png_path);

}  // namespace dgmm
