// The viewer under the shared virtual display: handwritten vtkInteractorEventRecorder streams
// drive the real interactor (slider drag, keys, hover), and saved PNGs are compared with the
// offscreen renderer's PNG of the same picture.
#include "render/viewer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "render/heat_map.h"
#include "render/slice_figure.h"
#include "tests/render/output_dir.h"
#include "tests/render/png_pixels.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

fs::path TempDir() {
  const fs::path dir = test::OutputPath("viewer");
  fs::create_directories(dir);
  return dir;
}

// Pose (dx, dy) and terrain (pitch, roll); two commands whose pose depends on the pitch (a
// correlation of 0.8), drawn at random from a seed.
MotionModel TerrainModel(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  MotionModel model;
  model.pose_dim = 2;
  model.terrain_dim = 2;
  model.pose_names = {"dx", "dy"};
  model.pose_units = {"m", "m"};
  model.terrain_names = {"pitch", "roll"};
  for (int command : {0, 1}) {
    Mixture m(4);
    for (int c = 0; c < 3; ++c) {
      Eigen::Vector4d mean(normal(rng), normal(rng), 0.2 * normal(rng), 0.2 * normal(rng));
      Eigen::Matrix4d s = Eigen::Matrix4d::Identity() * 0.3;
      s(0, 2) = s(2, 0) = 0.8 * std::sqrt(0.3 * 0.3);
      s(1, 3) = s(3, 1) = -0.5 * 0.3;
      m.Add(1.0 + c, Gaussian(mean, s));
    }
    model.mixtures[command] = m;
  }
  model.command_labels = {{0, "walk"}, {1, "turn"}};
  return model;
}

ExplorerOptions SmallFigure() {
  ExplorerOptions options;
  options.figure.width = 420;
  options.figure.height = 330;
  options.figure.grid = 90;
  return options;
}

// One line of a vtkInteractorEventRecorder stream (version 1.1):
// EventName X Y modifiers keycode repeat keysym.
std::string Event(const std::string& name, int x, int y, const std::string& key = "") {
  const int code = key.size() == 1 ? key[0] : 0;
  return name + " " + std::to_string(x) + " " + std::to_string(y) + " 0 " +
         std::to_string(code) + " 0 " + (key.empty() ? "0" : key) + "\n";
}
std::string Key(const std::string& key) {
  return Event("KeyPressEvent", 5, 5, key) + Event("CharEvent", 5, 5, key) +
         Event("KeyReleaseEvent", 5, 5, key);
}

// Press on slider i's tube at `fraction` of its length (the knob jumps there), release.
std::string DragSlider(const Viewer& viewer, int i, double fraction) {
  const auto p = viewer.SliderPixels(i);
  const int x = static_cast<int>(std::lround(p[0] + fraction * (p[2] - p[0])));
  const int y = static_cast<int>(std::lround(p[1]));
  return Event("MouseMoveEvent", x, y) + Event("LeftButtonPressEvent", x, y) +
         Event("MouseMoveEvent", x + 1, y) + Event("LeftButtonReleaseEvent", x + 1, y);
}

const std::string kHeader = "# StreamVersion 1.1\n";

// Number of pixels whose RGB differ between two images of equal size.
int DifferentPixels(const test::PngImage& a, const test::PngImage& b) {
  if (a.width != b.width || a.height != b.height) return -1;
  return static_cast<int>(((a.red - b.red).cwiseAbs() + (a.green - b.green).cwiseAbs() +
                           (a.blue - b.blue).cwiseAbs())
                              .unaryExpr([](double v) { return v > 0 ? 1.0 : 0.0; })
                              .sum());
}

// The offscreen `dgmm render` path (SliceHeatMaps + RenderHeatMap/Row) for the explorer's state.
void RenderLikeTheCommand(const SliceExplorer& explorer, const std::vector<SliceSource>& sources,
                          const SliceFigureOptions& figure, const std::string& png) {
  std::vector<const ModelSlice*> slices;
  for (const ModelSlice& s : explorer.slices()) slices.push_back(&s);
  // The automatic window, or the one `render --window` gets when zoomed or held by a slider.
  const PlotRange window = explorer.window();
  const auto panels = SliceHeatMaps(slices, sources, explorer.points(), window, figure);
  if (panels.size() == 1) {
    RenderHeatMap(panels[0], png);
  } else {
    RenderHeatMapRow(panels, png);
  }
}

TEST(ViewerTest, SliderDragChangesThePictureAndTheSavedPngEqualsTheRenderer) {
  const fs::path dir = TempDir();
  ExplorerInputs inputs;
  inputs.model = TerrainModel(11);
  inputs.model_file = "terrain.h5";
  const ExplorerOptions options = SmallFigure();
  ViewerOptions viewer_options;
  viewer_options.save_prefix = (dir / "single").string();
  Viewer viewer(SliceExplorer(inputs, options), viewer_options);
  const auto size = viewer.window_size();
  EXPECT_EQ(size[0], 420);
  EXPECT_GT(size[1], 330);

  viewer.Replay(kHeader + Key("s"));
  ASSERT_EQ(viewer.saved_files().size(), 1u);
  const double pitch_before = viewer.explorer().terrain()[0].value;

  viewer.Replay(kHeader + DragSlider(viewer, 0, 0.9) + Key("s"));
  ASSERT_EQ(viewer.saved_files().size(), 2u);
  const double pitch_after = viewer.explorer().terrain()[0].value;
  const TerrainSlider& slider = viewer.explorer().terrain()[0];
  // The knob jumped to ~90% of the span (a few pixels of the ~180-pixel tube either way).
  EXPECT_NEAR((pitch_after - slider.min) / (slider.max - slider.min), 0.9, 0.05);
  EXPECT_GT(std::abs(pitch_after - pitch_before), 0.2 * (slider.max - slider.min));

  const test::PngImage before = test::ReadPng(viewer.saved_files()[0]);
  const test::PngImage after = test::ReadPng(viewer.saved_files()[1]);
  ASSERT_EQ(after.width, 420);
  ASSERT_EQ(after.height, 330);
  // The conditional density moved: a good part of the plot area changed colour.
  EXPECT_GT(DifferentPixels(before, after), 420 * 330 / 20);

  // The same picture through the offscreen renderer: pixel-equal.
  const fs::path rendered = dir / "rendered.png";
  RenderLikeTheCommand(viewer.explorer(), {{"dgmm", "terrain.h5"}}, options.figure,
                       rendered.string());
  EXPECT_EQ(DifferentPixels(after, test::ReadPng(rendered.string())), 0)
      << viewer.saved_files()[1] << " vs " << rendered;
}

TEST(ViewerTest, KeysPickCommandsAxesEllipsesAndHoverReadsTheDensity) {
  const fs::path dir = TempDir();
  ExplorerInputs inputs;
  inputs.model = TerrainModel(12);
  inputs.model_file = "terrain.h5";
  ViewerOptions viewer_options;
  viewer_options.save_prefix = (dir / "keys").string();
  Viewer viewer(SliceExplorer(inputs, SmallFigure()), viewer_options);
  EXPECT_EQ(viewer.explorer().command_index(), 0);
  viewer.Replay(kHeader + Key("n"));
  EXPECT_EQ(viewer.explorer().command_index(), 1);
  // Typed label: "/", "w", Return picks "walk".
  viewer.Replay(kHeader + Key("slash") + Key("w") + Key("Return"));
  EXPECT_EQ(viewer.explorer().command_index(), 0);
  viewer.Replay(kHeader + Key("x"));
  EXPECT_EQ(viewer.explorer().slices()[0].x_index, 1);
  EXPECT_EQ(viewer.explorer().slices()[0].y_index, 0);

  viewer.Replay(kHeader + Key("s") + Key("g") + Key("s"));
  EXPECT_TRUE(viewer.explorer().ellipses());
  ASSERT_EQ(viewer.saved_files().size(), 2u);
  EXPECT_GT(DifferentPixels(test::ReadPng(viewer.saved_files()[0]),
                            test::ReadPng(viewer.saved_files()[1])),
            50);  // the ellipses were drawn

  // Hover over the mode of panel 0: the read-out names its density and a component.
  const Mixture& m = viewer.explorer().slices()[0].mixture;
  const Mixture::Mode mode = m.MaxDensity();
  const Eigen::Vector2d px = viewer.PanelPixel(0, mode.x(0), mode.x(1));
  viewer.Replay(kHeader + Event("MouseMoveEvent", static_cast<int>(std::lround(px(0))),
                                static_cast<int>(std::lround(px(1)))));
  EXPECT_NE(viewer.readout().find("p="), std::string::npos) << viewer.readout();
  EXPECT_NE(viewer.readout().find("component"), std::string::npos);
  // Outside every plot area (the control strip above the panels): no read-out.
  viewer.Replay(kHeader + Event("MouseMoveEvent", 3, viewer.window_size()[1] - 3));
  EXPECT_TRUE(viewer.readout().empty());
}

TEST(ViewerTest, ARecordedSessionReplaysToTheSameState) {
  const fs::path dir = TempDir();
  ExplorerInputs inputs;
  inputs.model = TerrainModel(15);
  inputs.model_file = "terrain.h5";
  const fs::path recording = dir / "session.events";
  std::string first_png;
  double pitch = 0;
  {
    ViewerOptions options;
    options.save_prefix = (dir / "recorded").string();
    options.record_file = recording.string();
    Viewer viewer(SliceExplorer(inputs, SmallFigure()), options);
    viewer.Replay(kHeader + Key("n") + DragSlider(viewer, 0, 0.3) + Key("Tab") + Key("period") +
                  Key("s"));
    pitch = viewer.explorer().terrain()[0].value;
    ASSERT_EQ(viewer.saved_files().size(), 1u);
    first_png = viewer.saved_files()[0];
  }
  std::ifstream in(recording);
  const std::string events((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(events.find("LeftButtonPressEvent"), std::string::npos);
  ViewerOptions options;
  options.save_prefix = (dir / "replayed").string();
  Viewer viewer(SliceExplorer(inputs, SmallFigure()), options);
  viewer.Replay(events);
  EXPECT_EQ(viewer.explorer().command_index(), 1);
  EXPECT_DOUBLE_EQ(viewer.explorer().terrain()[0].value, pitch);
  ASSERT_EQ(viewer.saved_files().size(), 1u);
  EXPECT_EQ(DifferentPixels(test::ReadPng(first_png), test::ReadPng(viewer.saved_files()[0])), 0);
}

TEST(ViewerTest, CompareShowsThreeLinkedPanelsEqualToTheRenderersRow) {
  const fs::path dir = TempDir();
  ExplorerInputs inputs;
  inputs.model = TerrainModel(13);
  inputs.model_file = "a.h5";
  inputs.compare = TerrainModel(14);
  inputs.compare_file = "b.h5";
  const ExplorerOptions options = SmallFigure();
  ViewerOptions viewer_options;
  viewer_options.save_prefix = (dir / "compare").string();
  Viewer viewer(SliceExplorer(inputs, options), viewer_options);
  EXPECT_EQ(viewer.window_size()[0], 3 * 420);
  // Zoom with the wheel over panel B: all three panels share the new window.
  const PlotRange before = viewer.explorer().window();
  const Eigen::Vector2d centre =
      viewer.PanelPixel(1, 0.5 * (before.x_min + before.x_max), 0.5 * (before.y_min + before.y_max));
  viewer.Replay(kHeader + DragSlider(viewer, 1, 0.2) +
                Event("MouseWheelForwardEvent", static_cast<int>(centre(0)),
                      static_cast<int>(centre(1))) +
                Key("s"));
  const PlotRange after = viewer.explorer().window();
  EXPECT_TRUE(viewer.explorer().window_locked());
  EXPECT_NEAR(after.x_max - after.x_min, 0.8 * (before.x_max - before.x_min),
              0.01 * (before.x_max - before.x_min));
  ASSERT_EQ(viewer.saved_files().size(), 1u);
  const test::PngImage saved = test::ReadPng(viewer.saved_files()[0]);
  EXPECT_EQ(saved.width, 3 * 420);
  // The renderer with the same window draws the same three panels.
  std::vector<const ModelSlice*> slices;
  for (const ModelSlice& s : viewer.explorer().slices()) slices.push_back(&s);
  const auto panels = SliceHeatMaps(slices, {{"dgmm", "a.h5"}, {"dgmm", "b.h5"}},
                                    viewer.explorer().points(), after, options.figure);
  const fs::path rendered = dir / "row.png";
  RenderHeatMapRow(panels, rendered.string());
  // Panels B and A - B sit in viewports offset by whole panel widths; the rasteriser's float
  // transform of (offset + x) may put a contour end lying on a pixel boundary on the other side,
  // so a handful of isolated line pixels may differ (none did for this seed; panel A, at the
  // window's origin, is held to exact equality in the single-panel test).
  constexpr int kBoundaryPixels = 40;  // 0.01% of the 1260 x 330 row
  EXPECT_LE(DifferentPixels(saved, test::ReadPng(rendered.string())), kBoundaryPixels);
}

}  // namespace
}  // namespace dgmm
