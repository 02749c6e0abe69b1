#include "render/chart.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/render/output_dir.h"
#include "tests/render/png_pixels.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// Pixels within +-20 of the colour in every channel (antialiasing blends edges).
int CountColour(const test::PngImage& image, std::array<int, 3> rgb) {
  int n = 0;
  for (int r = 0; r < image.height; ++r) {
    for (int c = 0; c < image.width; ++c) {
      n += std::abs(image.red(r, c) - rgb[0]) < 20 && std::abs(image.green(r, c) - rgb[1]) < 20 &&
           std::abs(image.blue(r, c) - rgb[2]) < 20;
    }
  }
  return n;
}

TEST(ChartTest, LineChartDrawsEverySeriesAtTheRequestedSize) {
  LineChartSpec spec;
  spec.title = "Gaussians after one pass";
  spec.x_label = "k";
  spec.y_label = "number of Gaussians";
  spec.log_x = true;
  spec.series.push_back({"faithful", {0.01, 0.1, 1, 10}, {30, 12, 3, 2}, {3, 2, 1, 0.5}, {{0, 114, 178}}});
  spec.series.push_back({"improved", {0.01, 0.1, 1, 10}, {9, 5, 2, 2}, {}, {{213, 94, 0}}});
  spec.width = 500;
  spec.height = 400;
  const fs::path png = test::OutputPath("line.png");
  RenderLineChart(spec, png.string());
  const test::PngImage image = test::ReadPng(png.string());
  ASSERT_EQ(image.width, 500);
  ASSERT_EQ(image.height, 400);
  EXPECT_GT(CountColour(image, {0, 114, 178}), 100);
  EXPECT_GT(CountColour(image, {213, 94, 0}), 100);
}

TEST(ChartTest, BarChartDrawsBars) {
  BarChartSpec spec;
  spec.title = "held-out log-likelihood";
  spec.categories = {"EM", "DGMM"};
  spec.series.push_back({"mean", {}, {-1.2, -1.5}, {0.1, 0.2}, {{0, 158, 115}}});
  const fs::path png = test::OutputPath("bar.png");
  RenderBarChart(spec, png.string());
  const test::PngImage image = test::ReadPng(png.string());
  ASSERT_EQ(image.width, 800);
  ASSERT_EQ(image.height, 600);
  EXPECT_GT(CountColour(image, {0, 158, 115}), 2000);  // two filled bars
}

TEST(ChartTest, InvalidSpecsThrowAndWriteNothing) {
  const fs::path png = test::OutputPath("bad.png");
  fs::remove(png);
  LineChartSpec line;
  EXPECT_THROW(RenderLineChart(line, png.string()), InputError);  // no series
  line.series.push_back({"s", {1, 2}, {1}, {}, {}});
  EXPECT_THROW(RenderLineChart(line, png.string()), InputError);  // ragged
  line.series[0] = {"s", {0, 2}, {1, 2}, {}, {}};
  line.log_x = true;
  EXPECT_THROW(RenderLineChart(line, png.string()), InputError);  // log of 0
  line.log_x = false;
  line.series[0].y[1] = NAN;
  EXPECT_THROW(RenderLineChart(line, png.string()), InputError);
  BarChartSpec bar;
  bar.categories = {"a", "b"};
  bar.series.push_back({"s", {}, {1, 2, 3}, {}, {}});
  EXPECT_THROW(RenderBarChart(bar, png.string()), InputError);
  EXPECT_FALSE(fs::exists(png));
}

}  // namespace
}  // namespace dgmm
