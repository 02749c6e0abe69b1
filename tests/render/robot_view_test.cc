// 3-D scenes of primitives (lib/render/robot_view.h): the height field of rough ground.
#include "render/robot_view.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <unistd.h>

#include "png_pixels.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// A 41 x 41 ground, 5 cm apart, flat or with a 0.3 m bump in the middle; seen from above.
SceneView Ground(double bump_m) {
  ScenePrimitive p;
  p.type = ScenePrimitive::Type::kHeightField;
  p.grid = 41;
  p.spacing = 0.05;
  p.rgba = Eigen::Vector4d(0.5, 0.5, 0.5, 1);
  for (int r = 0; r < p.grid; ++r) {
    for (int c = 0; c < p.grid; ++c) {
      const double x = (c - 20) * 0.05, y = (r - 20) * 0.05;
      p.heights.push_back(static_cast<float>(bump_m * std::exp(-(x * x + y * y) / (2 * 0.15 * 0.15))));
    }
  }
  SceneView view;
  view.primitives = {p};
  view.camera.position = Eigen::Vector3d(1.5, -1.5, 1.2);
  return view;
}

TEST(RobotViewTest, DrawsTheHeightFieldsRelief) {
  if (std::getenv("DISPLAY") == nullptr) GTEST_SKIP() << "not run under xvfb-run";
  const fs::path dir = fs::temp_directory_path() / ("dgmm_robot_view_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string flat = (dir / "flat.png").string(), bumpy = (dir / "bumpy.png").string();
  SceneStripOptions options;
  options.panel_width = 160;
  options.panel_height = 120;
  RenderSceneStrip({Ground(0)}, options, flat);
  RenderSceneStrip({Ground(0.3)}, options, bumpy);
  const test::PngImage a = test::ReadPng(flat), b = test::ReadPng(bumpy);
  ASSERT_EQ(a.width, 160);
  ASSERT_EQ(b.width, 160);
  // The ground covers part of the picture (not background white), and the bump changes it.
  EXPECT_LT(a.luminance.minCoeff(), 0.9 * 255);  // luminance in 0..255
  EXPECT_GT((a.luminance - b.luminance).cwiseAbs().mean(), 2.0);
  fs::remove_all(dir);
}

TEST(RobotViewTest, RefusesAHeightFieldOfTheWrongSize) {
  SceneView view = Ground(0.1);
  view.primitives[0].heights.pop_back();
  EXPECT_THROW(RenderSceneStrip({view}, SceneStripOptions(), "/tmp/never_written.png"), std::exception);
  EXPECT_FALSE(fs::exists("/tmp/never_written.png"));
}

}  // namespace
}  // namespace dgmm
