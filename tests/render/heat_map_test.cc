#include "render/heat_map.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/render/output_dir.h"
#include "tests/render/png_pixels.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// The densest bump (weight 3 at (1, 2)) dominates; a weaker one sits at (-1.5, -1).
Mixture TwoBumps() {
  Mixture m(2);
  m.Add(3, Gaussian(Eigen::Vector2d(1, 2), Eigen::Vector2d(0.3, 0.5).asDiagonal()));
  m.Add(1, Gaussian(Eigen::Vector2d(-1.5, -1), Eigen::Matrix2d::Identity() * 0.4));
  return m;
}

HeatMapSpec SpecOf(const Mixture& m, int width, int height) {
  HeatMapSpec spec;
  spec.background = MixtureDensityGrid(m, MixtureRange(m), 160, 160);
  spec.contours.push_back({spec.background, 5, {200, 200, 200}});
  spec.points.resize(3, 2);
  spec.points << 0, 0, 1, 1, -1, 2;
  spec.title = "two bumps";
  spec.x_label = "u (m)";
  spec.y_label = "v (rad)";
  spec.width = width;
  spec.height = height;
  return spec;
}

// The brightest blurred region must be within this many pixels of the projected mode: a few grid
// cells (the raster is 160 cells over ~500 pixels) plus the 5x5 blur.
constexpr double kModePixelTol = 8.0;

TEST(HeatMapTest, PngHasRequestedSizeAndBrightestRegionAtTheMode) {
  const Mixture m = TwoBumps();
  const fs::path png = test::OutputPath("single.png");
  const PlotLayout layout = RenderHeatMap(SpecOf(m, 640, 480), png.string());
  const test::PngImage image = test::ReadPng(png.string());
  ASSERT_EQ(image.width, 640);
  ASSERT_EQ(image.height, 480);
  EXPECT_GT(image.luminance.maxCoeff() - image.luminance.minCoeff(), 100);  // not uniform
  // The plot area is a sensible part of the image.
  EXPECT_GT(layout.right - layout.left, 0.5 * 640);
  EXPECT_GT(layout.top - layout.bottom, 0.5 * 480);
  EXPECT_LE(layout.right, 640);
  EXPECT_LE(layout.top, 480);

  const Eigen::Vector2d mode_px = layout.ToPixel(m.MaxDensity().x(0), m.MaxDensity().x(1));
  const Eigen::Vector2i bright =
      test::BrightestRegion(image, static_cast<int>(layout.left), static_cast<int>(layout.bottom),
                            static_cast<int>(layout.right), static_cast<int>(layout.top));
  EXPECT_NEAR(bright(0), mode_px(0), kModePixelTol);
  EXPECT_NEAR(bright(1), mode_px(1), kModePixelTol);
  // The weaker bump is darker than the main one.
  const Eigen::Vector2d weak_px = layout.ToPixel(-1.5, -1);
  EXPECT_LT(image.luminance(static_cast<int>(weak_px(1)), static_cast<int>(weak_px(0))),
            image.luminance(bright(1), bright(0)));
}

TEST(HeatMapTest, DiffRowPutsPanelsSideBySideWithSignedColours) {
  const Mixture a = TwoBumps();
  Mixture b(2);
  b.Add(1, Gaussian(Eigen::Vector2d(-1.5, 1.5), Eigen::Matrix2d::Identity() * 0.5));
  const PlotRange range{-4, 4, -4, 4};
  HeatMapSpec pa = SpecOf(a, 400, 360), pb = SpecOf(b, 400, 360), diff = SpecOf(a, 400, 360);
  pa.background = MixtureDensityGrid(a, range, 120, 120);
  pb.background = MixtureDensityGrid(b, range, 120, 120);
  diff.background = pa.background;
  diff.background.values -= pb.background.values;
  diff.palette = HeatMapSpec::Palette::kDiverging;
  diff.contours.clear();
  diff.points.resize(0, 2);
  const fs::path png = test::OutputPath("row.png");
  const auto layouts = RenderHeatMapRow({pa, pb, diff}, png.string());
  const test::PngImage image = test::ReadPng(png.string());
  ASSERT_EQ(image.width, 1200);
  ASSERT_EQ(image.height, 360);
  ASSERT_EQ(layouts.size(), 3u);
  EXPECT_GE(layouts[1].left, 400);
  EXPECT_GE(layouts[2].left, 800);
  // Panel B's brightest region is B's mode.
  const Eigen::Vector2d b_px = layouts[1].ToPixel(-1.5, 1.5);
  const Eigen::Vector2i bright = test::BrightestRegion(
      image, static_cast<int>(layouts[1].left), static_cast<int>(layouts[1].bottom),
      static_cast<int>(layouts[1].right), static_cast<int>(layouts[1].top));
  EXPECT_NEAR(bright(0), b_px(0), kModePixelTol);
  EXPECT_NEAR(bright(1), b_px(1), kModePixelTol);
  // In the difference A - B: red where A dominates, blue where B does.
  const Eigen::Vector2d a_in_diff = layouts[2].ToPixel(1, 2);
  const Eigen::Vector2d b_in_diff = layouts[2].ToPixel(-1.5, 1.5);
  const int ar = static_cast<int>(a_in_diff(1)), ac = static_cast<int>(a_in_diff(0));
  const int br = static_cast<int>(b_in_diff(1)), bc = static_cast<int>(b_in_diff(0));
  EXPECT_GT(image.red(ar, ac), image.blue(ar, ac) + 50);
  EXPECT_GT(image.blue(br, bc), image.red(br, bc) + 50);
}

TEST(HeatMapTest, InvalidSpecThrowsAndWritesNothing) {
  const fs::path png = test::OutputPath("invalid.png");
  fs::remove(png);
  HeatMapSpec spec = SpecOf(TwoBumps(), 640, 480);
  spec.background.values(3, 4) = NAN;
  EXPECT_THROW(RenderHeatMap(spec, png.string()), InputError);
  spec = SpecOf(TwoBumps(), 10, 10);  // too small
  EXPECT_THROW(RenderHeatMap(spec, png.string()), InputError);
  EXPECT_FALSE(fs::exists(png));
}

TEST(HeatMapTest, UnwritablePathThrowsInputError) {
  const HeatMapSpec spec = SpecOf(TwoBumps(), 320, 240);
  EXPECT_THROW(RenderHeatMap(spec, "/nonexistent-dir/x.png"), InputError);
}

}  // namespace
}  // namespace dgmm
