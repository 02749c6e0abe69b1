// End-to-end: `dgmm view --replay` drives the window with a recorded key stream, saves a PNG,
// prints the `dgmm render` command of the same picture, and that command writes the same PNG.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>

#include "core/motion_model.h"
#include "io/model_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

// Pose (dx, dy) and terrain (pitch, roll), three commands; the pose follows the pitch.
MotionModel TerrainModel(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  MotionModel model;
  model.pose_dim = 2;
  model.terrain_dim = 2;
  model.pose_names = {"dx", "dy"};
  model.pose_units = {"m", "m"};
  model.terrain_names = {"pitch", "roll"};
  model.command_dim_names = {"speed"};
  for (int command : {0, 1, 2}) {
    model.command_values[command] = Eigen::VectorXd::Constant(1, 0.5 * command);
    Mixture m(4);
    for (int c = 0; c < 2; ++c) {
      Eigen::Vector4d mean(normal(rng), normal(rng), 0.1 * normal(rng), 0.1 * normal(rng));
      Eigen::Matrix4d s = Eigen::Matrix4d::Identity() * 0.2;
      s(0, 2) = s(2, 0) = 0.15;
      m.Add(1.0 + c, Gaussian(mean, s));
    }
    model.mixtures[command] = m;
    model.command_labels[command] = "cmd" + std::to_string(command);
  }
  return model;
}

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The words after "same picture: dgmm " (quotes removed; no argument holds a space here).
std::vector<std::string> RenderCommandIn(const std::string& out) {
  const std::string marker = "same picture: dgmm ";
  auto at = out.find(marker);
  if (at == std::string::npos) return {};
  std::istringstream line(out.substr(at + marker.size(), out.find('\n', at) - at - marker.size()));
  std::vector<std::string> words;
  for (std::string w; line >> w;) {
    if (w.size() >= 2 && w.front() == '\'' && w.back() == '\'') w = w.substr(1, w.size() - 2);
    words.push_back(w);
  }
  return words;
}

// Key press, char and release, as vtkInteractorEventRecorder writes them (stream version 1.1).
std::string Key(const std::string& sym, int code) {
  std::string out;
  for (const char* e : {"KeyPressEvent", "CharEvent", "KeyReleaseEvent"}) {
    out += std::string(e) + " 10 10 0 " + std::to_string(code) + " 0 " + sym + "\n";
  }
  return out;
}

TEST(ViewCommandTest, ReplayedKeysSaveWhatRenderDraws) {
  const fs::path dir = MakeTempDir("view-command");
  const std::string model = (dir / "terrain.h5").string();
  WriteModel(TerrainModel(21), model);
  // Next command, select the second slider (roll), move it by +15%, zoom in, save.
  const fs::path events = dir / "events.txt";
  std::ofstream(events) << "# StreamVersion 1.1\n"
                        << Key("n", 'n') << Key("Tab", 9) << Key("period", '.')
                        << Key("period", '.') << Key("period", '.') << Key("plus", '+')
                        << Key("s", 's');
  const std::string prefix = (dir / "v").string();
  RunResult r = RunUnderXvfb({"view", model, "--condition", "pitch=0.05", "--size", "480x380",
                              "--grid", "80", "--replay", events.string(), "--save-prefix",
                              prefix},
                             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(prefix + "-1.png")) << r.out;
  EXPECT_NE(r.out.find("command cmd1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pitch=0.05"), std::string::npos) << r.out;

  std::vector<std::string> args = RenderCommandIn(r.out);
  ASSERT_GT(args.size(), 4u) << r.out;
  ASSERT_EQ(args[0], "render");
  EXPECT_NE(std::find(args.begin(), args.end(), "--window"), args.end());  // zoomed
  const fs::path rendered = dir / "rendered.png";
  auto o = std::find(args.begin(), args.end(), "-o");
  ASSERT_NE(o, args.end());
  *(o + 1) = rendered.string();
  RunResult render = RunUnderXvfb(args, dir);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  // Same pixels and the same PNG encoder: the files are identical.
  const std::string saved = Bytes(prefix + "-1.png");
  EXPECT_GT(saved.size(), 1000u);
  EXPECT_TRUE(saved == Bytes(rendered)) << "view and render PNGs differ";
}

TEST(ViewCommandTest, NoDisplayAndBadInputAreCleanErrors) {
  const fs::path dir = MakeTempDir("view-errors");
  const std::string model = (dir / "terrain.h5").string();
  WriteModel(TerrainModel(22), model);
  for (const std::string display : {"DISPLAY=:4711", "DISPLAY="}) {
    RunResult r = RunDgmm({"view", model}, {display});
    EXPECT_EQ(r.exit_code, 1);  // not a crash (-1), not a hang
    EXPECT_NE(r.err.find("cannot open an X display for rendering"), std::string::npos) << r.err;
    EXPECT_EQ(CountLines(r.err), 1);
  }
  MotionModel other = TerrainModel(23);
  other.pose_names = {"forward", "lateral"};
  const std::string other_path = (dir / "other.h5").string();
  WriteModel(other, other_path);
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"view", model, "--compare", other_path},
           {"view", model, "--command", "nope"},
           {"view", model, "--x-dim", "pitch"},
           {"view", model, "--condition", "yaw=1"}}) {
    RunResult r = RunUnderXvfb(args, dir);
    EXPECT_EQ(r.exit_code, 2) << args[2];  // bad input (app/main.cc)
    EXPECT_NE(r.err.find("dgmm: error:"), std::string::npos) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
  }
}

}  // namespace
}  // namespace dgmm::test
