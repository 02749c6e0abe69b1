// End-to-end: `dgmm render` and `dgmm plot` under xvfb-run, and their clean failure without a
// display. Pixels are checked in tests/render; here the command, its JSON and its files.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/mixture.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/model_slice.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

// Width and height from the PNG's IHDR chunk (bytes 16..23, big-endian).
std::pair<int, int> PngSize(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  unsigned char h[24] = {};
  in.read(reinterpret_cast<char*>(h), 24);
  if (!in || h[1] != 'P' || h[2] != 'N' || h[3] != 'G') return {-1, -1};
  auto be = [&](int o) { return (h[o] << 24) | (h[o + 1] << 16) | (h[o + 2] << 8) | h[o + 3]; };
  return {be(16), be(20)};
}

class RenderCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(MakeTempDir("render-command"));
    set_ = (*dir_ / "of.h5").string();
    ASSERT_EQ(RunDgmm({"import", SourcePath("datasets/old_faithful.csv").string(), "-o", set_,
                       "--pose-cols", "eruptions,waiting", "--standardize"})
                  .exit_code,
              0);
    for (int seed : {1, 2}) {
      std::string model = (*dir_ / ("m" + std::to_string(seed) + ".h5")).string();
      ASSERT_EQ(RunDgmm({"fit", set_, "-o", model, "--k", "0.7", "--seed",
                         std::to_string(seed)}).exit_code, 0);
    }
  }
  static fs::path Path(const std::string& name) { return *dir_ / name; }
  static inline fs::path* dir_ = nullptr;
  static inline std::string set_;
};

TEST_F(RenderCommandTest, HeatMapWithDataReportsLayoutAndMode) {
  const fs::path png = Path("heat.png");
  RunResult r = RunUnderXvfb({"render", Path("m1.h5").string(), "-o", png.string(), "--data",
                              set_, "--size", "640x480", "--json"}, *dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(PngSize(png), std::make_pair(640, 480));
  nlohmann::json j = nlohmann::json::parse(r.out);
  const auto& panel = j["panels"][0];
  // The mode reported is the model's (raw units) and projects inside the plot area.
  const MotionModel model = ReadModel(Path("m1.h5").string());
  const Mixture::Mode mode = RawMixture(model, 0).MaxDensity();
  EXPECT_NEAR(panel["mode"]["x"].get<double>(), mode.x(0), 1e-6 * (1 + std::abs(mode.x(0))));
  EXPECT_NEAR(panel["mode"]["y"].get<double>(), mode.x(1), 1e-6 * (1 + std::abs(mode.x(1))));
  const double px = panel["mode"]["pixel"][0], py = panel["mode"]["pixel"][1];
  EXPECT_GT(px, panel["plot_area_px"]["left"].get<double>());
  EXPECT_LT(px, panel["plot_area_px"]["right"].get<double>());
  EXPECT_GT(py, panel["plot_area_px"]["bottom"].get<double>());
  EXPECT_LT(py, panel["plot_area_px"]["top"].get<double>());
}

TEST_F(RenderCommandTest, DiffWritesThreePanels) {
  const fs::path png = Path("diff.png");
  RunResult r = RunUnderXvfb({"render", "--diff", Path("m1.h5").string(), Path("m2.h5").string(),
                              "-o", png.string(), "--size", "500x400", "--json"}, *dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(PngSize(png), std::make_pair(1500, 400));
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["panels"].size(), 3u);
  EXPECT_GE(j["ise_of_slices"].get<double>(), 0.0);
}

TEST_F(RenderCommandTest, DiffSharesOneScaleKeepsDataInsideAndLabelsAxes) {
  const fs::path png = Path("diff_data.png");
  RunResult r = RunUnderXvfb({"render", "--diff", Path("m1.h5").string(), Path("m2.h5").string(),
                              "--data", set_, "--labels", "seed 1,seed 2", "-o", png.string(),
                              "--size", "500x400", "--json"}, *dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  // A and B on one colour scale; the difference symmetric about 0.
  EXPECT_EQ(j["panels"][0]["color_range"], j["panels"][1]["color_range"]);
  EXPECT_DOUBLE_EQ(j["panels"][2]["color_range"][0].get<double>(),
                   -j["panels"][2]["color_range"][1].get<double>());
  // Every sample (raw units) inside the window.
  const SampleSet set = ReadSampleSet(set_);
  const auto range = j["panels"][0]["range"];
  for (int i = 0; i < set.size(); ++i) {
    const double x = set.transform.offset(0) + set.transform.scale(0) * set.x(i, 0);
    const double y = set.transform.offset(1) + set.transform.scale(1) * set.x(i, 1);
    EXPECT_GE(x, range[0].get<double>());
    EXPECT_LE(x, range[1].get<double>());
    EXPECT_GE(y, range[2].get<double>());
    EXPECT_LE(y, range[3].get<double>());
  }
  // Axis titles name the dimension and say what is known of its unit.
  for (const auto& panel : j["panels"]) {
    EXPECT_NE(panel["axis_titles"][0].get<std::string>().find("eruptions ("), std::string::npos);
    EXPECT_NE(panel["axis_titles"][1].get<std::string>().find("waiting ("), std::string::npos);
  }
}

TEST_F(RenderCommandTest, BadArgumentsFailWithOneLineAndNoFile) {
  const fs::path png = Path("bad.png");
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"render", Path("m1.h5").string(), "-o", png.string(), "--x-dim", "nope"},
           {"render", "--diff", Path("m1.h5").string(), "-o", png.string()},
           {"render", Path("m1.h5").string(), "-o", png.string(), "--size", "12"},
           {"render", Path("m1.h5").string(), "-o", png.string(), "--condition", "waiting"},
           {"render", set_, "-o", png.string()},
           {"render", Path("m1.h5").string(), "-o", png.string(), "--color-scale", "loud"}}) {
    RunResult r = RunUnderXvfb(args, *dir_);
    EXPECT_NE(r.exit_code, 0) << args[2];
    EXPECT_NE(r.err.find("dgmm: error:"), std::string::npos) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_FALSE(fs::exists(png));
  }
}

TEST_F(RenderCommandTest, NoDisplayIsACleanError) {
  const fs::path png = Path("nodisplay.png");
  for (const std::string display : {"DISPLAY=:4711", "DISPLAY="}) {
    RunResult r = RunDgmm({"render", Path("m1.h5").string(), "-o", png.string()}, {display});
    EXPECT_EQ(r.exit_code, 1);  // not a crash (-1)
    EXPECT_NE(r.err.find("cannot open an X display for rendering"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("xvfb-run -a"), std::string::npos);
    EXPECT_EQ(CountLines(r.err), 1);
    EXPECT_FALSE(fs::exists(png));
  }
}

TEST_F(RenderCommandTest, PlotDrawsCsvColumns) {
  const fs::path csv = Path("curve.csv"), png = Path("curve.png");
  std::ofstream(csv) << "k,mean,sd\n0.01,20,3\n0.1,9,2\n1,3,1\n10,2,0.5\n";
  RunResult r = RunUnderXvfb({"plot", "--csv", csv.string(), "--x", "k", "--y", "mean", "--yerr",
                              "sd", "--log-x", "-o", png.string(), "--size", "400x300"}, *dir_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(PngSize(png), std::make_pair(400, 300));
  r = RunUnderXvfb({"plot", "--csv", csv.string(), "--x", "k", "--y", "nope", "-o",
                    Path("bad_plot.png").string()}, *dir_);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_FALSE(fs::exists(Path("bad_plot.png")));
}

}  // namespace
}  // namespace dgmm::test
