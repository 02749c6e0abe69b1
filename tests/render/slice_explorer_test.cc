// The viewer's state without a window: conditioning, picks, samples near the terrain, the
// window and the equivalent `dgmm render` arguments.
#include "render/slice_explorer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "util/error.h"

namespace dgmm {
namespace {

// Pose (dx, dy, dz) and terrain (pitch); commands 2 ("up") and 5 ("down").
MotionModel ThreePoseModel() {
  MotionModel model;
  model.pose_dim = 3;
  model.terrain_dim = 1;
  model.pose_names = {"dx", "dy", "dz"};
  model.terrain_names = {"pitch"};
  Eigen::Matrix4d s;
  s << 1.0, 0.2, 0.1, 0.6,  //
      0.2, 1.0, 0.0, -0.3,  //
      0.1, 0.0, 1.0, 0.0,   //
      0.6, -0.3, 0.0, 1.0;
  for (int id : {2, 5}) {
    Mixture m(4);
    m.Add(3, Gaussian(Eigen::Vector4d(id, 0, 1, 0.2), s));
    m.Add(1, Gaussian(Eigen::Vector4d(-id, 2, 0, -0.2), 0.5 * s));
    model.mixtures[id] = m;
  }
  model.command_labels = {{2, "up"}, {5, "down"}};
  return model;
}

// 40 samples per command with pitch spread over [-1, 1]; command index = model id.
SampleSet SamplesFor(const MotionModel& model, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  SampleSet set;
  set.x_names = {"dx", "dy", "dz"};
  set.z_names = {"pitch"};
  set.commands.resize(6, 0);
  set.command_labels = {"0", "1", "up", "3", "4", "down"};
  std::vector<int> commands;
  std::vector<Eigen::VectorXd> ys;
  for (int id : {2, 5}) {
    Eigen::MatrixXd draws = model.MixtureFor(id).Sample(40, rng);
    for (int i = 0; i < 40; ++i) {
      commands.push_back(id);
      ys.push_back(draws.col(i));
    }
  }
  const int n = static_cast<int>(ys.size());
  set.command.resize(n);
  set.x.resize(n, 3);
  set.z.resize(n, 1);
  for (int i = 0; i < n; ++i) {
    set.command(i) = commands[i];
    set.x.row(i) = ys[i].head(3).transpose();
    set.z(i, 0) = ys[i](3);
  }
  return set;
}

ExplorerInputs Inputs(bool with_data) {
  ExplorerInputs in;
  in.model = ThreePoseModel();
  in.model_file = "m.h5";
  if (with_data) {
    in.data = SamplesFor(in.model, 3);
    in.data_file = "s.h5";
  }
  return in;
}

TEST(SliceExplorerTest, SliderConditionsLikeTheModelSlice) {
  SliceExplorer explorer(Inputs(false), {});
  ASSERT_EQ(explorer.terrain().size(), 1u);
  explorer.SetTerrain(0, 0.7);
  SliceSpec spec{"up", "dx", "dy", {{"pitch", 0.7}}, true};
  const ModelSlice reference = SliceModel(ThreePoseModel(), spec, "m.h5");
  for (double u : {-2.0, 0.5, 2.5}) {
    for (double v : {-1.0, 1.0}) {
      const Eigen::Vector2d p(u, v);
      EXPECT_NEAR(explorer.slices()[0].mixture.LogDensity(p), reference.mixture.LogDensity(p),
                  1e-12);
    }
  }
  // Moving the slider moves the density (the pose is correlated with the pitch).
  const Eigen::Vector2d p(2.0, 0.0);
  const double at_07 = explorer.slices()[0].mixture.LogDensity(p);
  explorer.SetTerrain(0, -0.7);
  EXPECT_GT(std::abs(explorer.slices()[0].mixture.LogDensity(p) - at_07), 0.1);
  // Marginal over the terrain when conditioning is off.
  explorer.ToggleConditioned();
  EXPECT_NE(explorer.slices()[0].description.find("marginal over dz,pitch"), std::string::npos)
      << explorer.slices()[0].description;
}

TEST(SliceExplorerTest, PicksCycleAndResolveLabels) {
  SliceExplorer explorer(Inputs(false), {});
  EXPECT_EQ(explorer.command_labels(), (std::vector<std::string>{"up", "down"}));
  explorer.StepCommand(1);
  EXPECT_EQ(explorer.slices()[0].command, 5);
  explorer.StepCommand(1);
  EXPECT_EQ(explorer.slices()[0].command, 2);
  EXPECT_TRUE(explorer.PickCommand("do"));
  EXPECT_EQ(explorer.slices()[0].command, 5);
  EXPECT_FALSE(explorer.PickCommand("sideways"));
  explorer.StepX(1);  // dx -> dy, the y axis: the axes swap
  EXPECT_EQ(explorer.slices()[0].x_index, 1);
  EXPECT_EQ(explorer.slices()[0].y_index, 0);
  explorer.StepY(-1);  // dx -> dz (cyclic)
  EXPECT_EQ(explorer.slices()[0].x_index, 1);
  EXPECT_EQ(explorer.slices()[0].y_index, 2);
}

TEST(SliceExplorerTest, SamplesNearTheTerrainAreASubsetThatFollowsTheSlider) {
  ExplorerOptions options;
  options.near_fraction = 0.1;
  SliceExplorer explorer(Inputs(true), options);
  const TerrainSlider s = explorer.terrain()[0];
  const SampleSet set = SamplesFor(ThreePoseModel(), 3);
  // Slider span = the data's pitch range.
  EXPECT_DOUBLE_EQ(s.min, set.z.col(0).minCoeff());
  EXPECT_DOUBLE_EQ(s.max, set.z.col(0).maxCoeff());
  // Reference count: samples of "up" (id 2) with |pitch - value| <= 0.1 * span.
  auto expected = [&](double value) {
    int n = 0;
    for (int i = 0; i < set.size(); ++i) {
      n += set.command(i) == 2 && std::abs(set.z(i, 0) - value) <= 0.1 * (s.max - s.min);
    }
    return n;
  };
  for (double value : {s.min, 0.5 * (s.min + s.max), s.max}) {
    explorer.SetTerrain(0, value);
    EXPECT_EQ(explorer.points().rows(), expected(value));
  }
  explorer.ToggleConditioned();
  EXPECT_EQ(explorer.points().rows(), 40);  // all samples of the command
  EXPECT_FALSE(explorer.RenderArguments("x.png").empty());
  explorer.ToggleConditioned();
  EXPECT_TRUE(explorer.RenderArguments("x.png").empty());  // render cannot filter by terrain
}

TEST(SliceExplorerTest, RenderArgumentsCarryExactValuesAndTheZoomedWindow) {
  SliceExplorer explorer(Inputs(false), {});
  explorer.SetTerrain(0, 0.1234567890123);
  explorer.Zoom(0.5, 0, 0);
  const auto args = explorer.RenderArguments("out.png");
  auto after = [&](const std::string& flag) {
    auto it = std::find(args.begin(), args.end(), flag);
    return it == args.end() || it + 1 == args.end() ? std::string() : *(it + 1);
  };
  EXPECT_EQ(after("--command"), "up");
  EXPECT_EQ(std::stod(after("--condition").substr(6)), explorer.terrain()[0].value);
  EXPECT_NE(std::find(args.begin(), args.end(), "--marginalise"), args.end());  // dz left over
  const PlotRange w = explorer.window();
  double x0, x1, y0, y1;
  ASSERT_EQ(std::sscanf(after("--window").c_str(), "%lf,%lf,%lf,%lf", &x0, &x1, &y0, &y1), 4);
  EXPECT_EQ(x0, w.x_min);
  EXPECT_EQ(y1, w.y_max);
  explorer.ResetWindow();
  EXPECT_FALSE(explorer.window_locked());
}

// A terrain move holds the window (axes stay put while the density moves); the held window is
// printed for `render` like a zoomed one, and a change of command frames the picture again.
TEST(SliceExplorerTest, TerrainMovesHoldTheWindowUntilTheCommandChanges) {
  SliceExplorer explorer(Inputs(false), {});
  const TerrainSlider s = explorer.terrain()[0];
  explorer.SetTerrain(0, s.min);
  const PlotRange held = explorer.window();
  EXPECT_TRUE(explorer.window_locked());
  explorer.SetTerrain(0, s.max);
  EXPECT_EQ(explorer.window().x_min, held.x_min);
  EXPECT_EQ(explorer.window().y_max, held.y_max);
  const auto args = explorer.RenderArguments("out.png");
  EXPECT_NE(std::find(args.begin(), args.end(), "--window"), args.end());
  // Re-framed at the same terrain, the automatic window differs from the held one.
  explorer.ResetWindow();
  const PlotRange framed = explorer.window();
  EXPECT_FALSE(framed.x_min == held.x_min && framed.x_max == held.x_max &&
               framed.y_min == held.y_min && framed.y_max == held.y_max);
  explorer.SetTerrain(0, s.min);
  explorer.StepCommand(1);
  EXPECT_FALSE(explorer.window_locked());
  // A user's zoom is not released by a change of command.
  explorer.Zoom(0.5, 0, 0);
  explorer.SetTerrain(0, s.max);
  explorer.StepCommand(1);
  EXPECT_TRUE(explorer.window_locked());
}

TEST(SliceExplorerTest, BadInputsNameTheFile) {
  ExplorerOptions options;
  options.x_dim = "pitch";  // terrain, not pose
  EXPECT_THROW(SliceExplorer(Inputs(false), options), InputError);
  ExplorerInputs in = Inputs(false);
  in.compare = ThreePoseModel();
  in.compare->command_labels = {{2, "left"}, {5, "right"}};
  in.compare_file = "b.h5";
  try {
    SliceExplorer explorer(in, {});
    FAIL() << "no command in common must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.h5"), std::string::npos);
  }
  ExplorerOptions nan;
  nan.terrain = {{"pitch", NAN}};
  EXPECT_THROW(SliceExplorer(Inputs(false), nan), InputError);
}

TEST(SliceExplorerTest, EllipsesAreTwoSigmaContours) {
  Mixture m(2);
  Eigen::Matrix2d s;
  s << 2.0, 0.6, 0.6, 0.5;
  m.Add(1, Gaussian(Eigen::Vector2d(1, -1), s));
  const auto curves = ComponentEllipses(m, 32);
  ASSERT_EQ(curves.size(), 1u);
  for (Eigen::Index r = 0; r < curves[0].points.rows(); ++r) {
    const Eigen::Vector2d p = curves[0].points.row(r).transpose();
    EXPECT_NEAR(m.component(0).SquaredMahalanobis(p), 4.0, 1e-9);
  }
}

}  // namespace
}  // namespace dgmm
