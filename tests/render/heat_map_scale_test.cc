// Figures a reader can read at a glance: each test below fails on the heat maps dgmm drew before
// issue #11 (a peaked model as a black field, a spike setting the difference scale, panels with
// their own scales, numeric axes where names belong, cut titles, faint dots, oversized windows).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "render/density_grid.h"
#include "render/heat_map.h"
#include "render/text_fit.h"
#include "tests/render/output_dir.h"
#include "tests/render/png_pixels.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// 80% of the weight in a narrow component, 20% in a broad one (peak densities 400:1): what one
// dominant Gaussian of a DGMM looks like.
Mixture Peaked() {
  Mixture m(2);
  m.Add(0.8, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 0.05 * 0.05));
  m.Add(0.2, Gaussian(Eigen::Vector2d(0.5, 0.3), Eigen::Matrix2d::Identity() * 0.5 * 0.5));
  return m;
}

// Share of the plot area's pixels brighter than the darkest colours of the ramp.
double NonDarkShare(const test::PngImage& image, const PlotLayout& l) {
  int bright = 0, all = 0;
  for (int r = static_cast<int>(l.bottom) + 2; r < static_cast<int>(l.top) - 2; ++r) {
    for (int c = static_cast<int>(l.left) + 2; c < static_cast<int>(l.right) - 2; ++c) {
      ++all;
      if (image.luminance(r, c) > 30) ++bright;  // the ramp's darkest tenth is below 30
    }
  }
  return static_cast<double>(bright) / all;
}

TEST(HeatMapScale, PeakedModelIsNotABlackField) {
  const Mixture m = Peaked();
  HeatMapSpec spec;
  spec.background = MixtureDensityGrid(m, ExtentRange({&m}, Eigen::MatrixX2d(0, 2)), 150, 150);
  spec.width = 500;
  spec.height = 420;
  spec.color_scale = HeatMapSpec::ColorScale::kLinear;  // the old drawing
  const PlotLayout linear = RenderHeatMap(spec, test::OutputPath("linear.png").string());
  const double linear_share = NonDarkShare(test::ReadPng(test::OutputPath("linear.png").string()), linear);
  spec.color_scale = HeatMapSpec::ColorScale::kAuto;
  EXPECT_EQ(ResolveColorScale(spec), HeatMapSpec::ColorScale::kLog);
  const PlotLayout automatic = RenderHeatMap(spec, test::OutputPath("auto.png").string());
  const double auto_share = NonDarkShare(test::ReadPng(test::OutputPath("auto.png").string()), automatic);
  EXPECT_LT(linear_share, 0.1) << "the linear scale shows one bright spot";
  EXPECT_GT(auto_share, 0.4) << "the log scale shows where the broad component lies";
  // Quantile: every colour covers the same area, so half the plot is in the upper half.
  spec.color_scale = HeatMapSpec::ColorScale::kQuantile;
  const PlotLayout quantile = RenderHeatMap(spec, test::OutputPath("quantile.png").string());
  EXPECT_GT(NonDarkShare(test::ReadPng(test::OutputPath("quantile.png").string()), quantile), 0.5);
  // A broad model keeps the linear scale under auto.
  Mixture broad(2);
  broad.Add(1, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity()));
  spec.background = MixtureDensityGrid(broad, MixtureRange(broad, 2.0), 60, 60);
  spec.color_scale = HeatMapSpec::ColorScale::kAuto;
  EXPECT_EQ(ResolveColorScale(spec), HeatMapSpec::ColorScale::kLinear);
}

TEST(HeatMapScale, DifferenceScaleIsSymmetricAndNotSetByOneSpike) {
  // A smooth difference in [-1, 1] plus one spike of 100.
  DensityGrid diff = SampleGrid([](double x, double) { return x; }, {-1, 1, -1, 1}, 100, 100);
  diff.values(50, 50) = 100;
  HeatMapSpec spec;
  spec.background = diff;
  spec.palette = HeatMapSpec::Palette::kDiverging;
  spec.width = 500;
  spec.height = 420;
  const PlotLayout l = RenderHeatMap(spec, test::OutputPath("diff.png").string());
  EXPECT_DOUBLE_EQ(l.color_min, -l.color_max);
  EXPECT_LT(l.color_max, 1.5) << "the 99th percentile of |diff|, not the spike";
  EXPECT_GT(l.color_max, 0.9);
  // x = 0.7 reads as clearly red (with the spike's scale it was all but grey).
  const test::PngImage image = test::ReadPng(test::OutputPath("diff.png").string());
  const Eigen::Vector2d px = l.ToPixel(0.7, -0.5);
  const int r = static_cast<int>(px(1)), c = static_cast<int>(px(0));
  EXPECT_GT(image.red(r, c), image.blue(r, c) + 80);
}

TEST(HeatMapScale, BeforeAndAfterPanelsShareOneScale) {
  Mixture a(2), b(2);
  a.Add(1, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 0.2));
  b.Add(1, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 0.8));  // 4x lower peak
  const PlotRange range{-3, 3, -3, 3};
  HeatMapSpec pa, pb;
  pa.background = MixtureDensityGrid(a, range, 80, 80);
  pb.background = MixtureDensityGrid(b, range, 80, 80);
  for (HeatMapSpec* p : {&pa, &pb}) {
    p->width = 420;
    p->height = 380;
    p->color_max = pa.background.values.maxCoeff();
  }
  const auto layouts = RenderHeatMapRow({pa, pb}, test::OutputPath("shared.png").string());
  EXPECT_EQ(layouts[0].color_max, layouts[1].color_max);
  // B's peak is a quarter of A's: on the shared scale it is clearly darker than A's.
  const test::PngImage image = test::ReadPng(test::OutputPath("shared.png").string());
  const Eigen::Vector2d pa_px = layouts[0].ToPixel(0, 0), pb_px = layouts[1].ToPixel(0, 0);
  EXPECT_GT(image.luminance(static_cast<int>(pa_px(1)), static_cast<int>(pa_px(0))),
            image.luminance(static_cast<int>(pb_px(1)), static_cast<int>(pb_px(0))) + 60);
}

TEST(HeatMapScale, CategoryAxesAndAxisTitlesAreDrawn) {
  HeatMapSpec spec;
  spec.background = SampleGrid([](double x, double y) { return x + y; }, {0, 3, 0, 2}, 30, 20);
  spec.palette = HeatMapSpec::Palette::kDiverging;
  spec.x_categories = {"flat", "uphill", "downhill"};
  spec.y_categories = {"forward", "turn_left"};
  spec.x_label = "terrain region";
  spec.y_label = "command";
  spec.width = 520;
  spec.height = 400;
  const PlotLayout l = RenderHeatMap(spec, test::OutputPath("categories.png").string());
  EXPECT_EQ(l.x_ticks, spec.x_categories);
  EXPECT_EQ(l.y_ticks, spec.y_categories);
  EXPECT_EQ(l.x_title, "terrain region");
  EXPECT_EQ(l.y_title, "command");
}

// The sim2real deficit map's layout (lib/sim2real/figures.cc): a 640-pixel panel with a colour
// bar and three terrain regions named on two lines. Before issue #24 the second lines ("pitch
// -8.9 deg, roll -11.2 deg", ~160 px in the axis font) overlapped their neighbours.
TEST(HeatMapScale, CategoryLabelsOfNeighboursDoNotOverlap) {
  HeatMapSpec spec;
  spec.background = SampleGrid([](double x, double y) { return x - y; }, {0, 3, 0, 4}, 48, 64);
  spec.palette = HeatMapSpec::Palette::kDiverging;
  spec.x_categories = {"right side up\npitch -8.9 deg, roll -11.2 deg",
                       "left side up\npitch -4.5 deg, roll +14.2 deg",
                       "nose down\npitch +15.7 deg, roll -3.7 deg"};
  spec.y_categories = {"+0.5,+0.5,+0.5", "0,0,-0.5", "-0.5,0,0", "-0.5,-0.5,-0.5"};
  spec.x_label = "terrain region (k-means of the terrain z)";
  spec.y_label = "command";
  spec.width = 640;
  spec.height = 420;
  for (bool row : {false, true}) {
    std::vector<PlotLayout> layouts;
    if (row) {
      layouts = RenderHeatMapRow({spec, spec}, test::OutputPath("label_row.png").string());
    } else {
      layouts = {RenderHeatMap(spec, test::OutputPath("labels.png").string())};
    }
    for (const PlotLayout& l : layouts) {
      ASSERT_EQ(l.x_tick_boxes.size(), 3u);
      for (size_t i = 0; i < l.x_tick_boxes.size(); ++i) {
        const auto& box = l.x_tick_boxes[i];
        EXPECT_GT(box[1] - box[0], 20) << "a measured label has a width";
        EXPECT_GE(box[0], 0);
        EXPECT_LE(box[1], l.width);
        if (i + 1 < l.x_tick_boxes.size()) {
          EXPECT_LT(box[1], l.x_tick_boxes[i + 1][0])
              << "label " << i << " overlaps label " << i + 1 << ": " << l.x_ticks[i];
        }
      }
      // Every word of every name is still there (wrapped, perhaps in a smaller font).
      for (size_t i = 0; i < spec.x_categories.size(); ++i) {
        std::string drawn = l.x_ticks[i], given = spec.x_categories[i];
        std::replace(drawn.begin(), drawn.end(), '\n', ' ');
        std::replace(given.begin(), given.end(), '\n', ' ');
        EXPECT_EQ(drawn, given);
      }
    }
  }
}

TEST(HeatMapScale, FitCategoryLabelsWrapsThenShrinks) {
  auto width = [](const std::string& text, int size) { return TextWidthPx(text, size); };
  // Fits as it is: unchanged.
  FittedLabels f = FitCategoryLabels({"flat", "uphill"}, 100, 12, 8, width);
  EXPECT_TRUE(f.fits);
  EXPECT_EQ(f.labels, (std::vector<std::string>{"flat", "uphill"}));
  EXPECT_EQ(f.font_size, 12);
  // Too wide on one line: wrapped at spaces, font kept.
  f = FitCategoryLabels({"pitch -8.9 deg, roll -11.2 deg"}, 110, 12, 8, width);
  EXPECT_TRUE(f.fits);
  EXPECT_EQ(f.font_size, 12);
  EXPECT_NE(f.labels[0].find('\n'), std::string::npos);
  for (size_t start = 0, end; start <= f.labels[0].size(); start = end + 1) {
    end = f.labels[0].find('\n', start);
    if (end == std::string::npos) end = f.labels[0].size();
    EXPECT_LE(width(f.labels[0].substr(start, end - start), 12), 110);
  }
  // A single word too wide at 12 pt: a smaller font.
  f = FitCategoryLabels({"downhill-sideways"}, 90, 12, 8, width);
  EXPECT_TRUE(f.fits);
  EXPECT_LT(f.font_size, 12);
  // Nothing fits: the smallest font, reported as not fitting.
  f = FitCategoryLabels({"an-unbreakable-very-long-region-name"}, 40, 12, 8, width);
  EXPECT_FALSE(f.fits);
  EXPECT_EQ(f.font_size, 8);
}

TEST(HeatMapScale, LongTitlesFitTheImage) {
  const std::string title =
      "p(dx, dy | command +0.5,0,-0.5, pitch=0.31, roll=-0.12) in cell forward x downhill: "
      "sim-trained model before the correction";
  const auto [text, size] = FitTitle(title, 520);
  EXPECT_LE(TextWidthPx(text, size), 520 - 40);
  HeatMapSpec spec;
  spec.background = SampleGrid([](double x, double y) { return x * y; }, {0, 1, 0, 1}, 20, 20);
  spec.title = title;
  spec.width = 520;
  spec.height = 420;
  const PlotLayout l = RenderHeatMap(spec, test::OutputPath("title.png").string());
  EXPECT_NE(l.title.find('\n'), std::string::npos);
  // Nothing dark touches the left or right edge in the title band (a cut title does).
  const test::PngImage image = test::ReadPng(test::OutputPath("title.png").string());
  for (int r = image.height - 40; r < image.height; ++r) {
    for (int c : {0, 1, 2, image.width - 3, image.width - 2, image.width - 1}) {
      EXPECT_GT(image.luminance(r, c), 200) << "row " << r << " col " << c;
    }
  }
}

TEST(HeatMapScale, DataPointsAreVisibleAndInsideTheWindow) {
  const Mixture m = Peaked();
  Eigen::MatrixX2d points(3, 2);
  points << 0.0, 0.0, 1.8, -1.2, -0.9, 1.6;  // two far outside the model's bulk
  const PlotRange range = ExtentRange({&m}, points);
  for (int i = 0; i < points.rows(); ++i) {
    EXPECT_GE(points(i, 0), range.x_min);
    EXPECT_LE(points(i, 0), range.x_max);
    EXPECT_GE(points(i, 1), range.y_min);
    EXPECT_LE(points(i, 1), range.y_max);
  }
  HeatMapSpec spec;
  spec.background = MixtureDensityGrid(m, range, 100, 100);
  spec.points = points;
  spec.width = 500;
  spec.height = 420;
  const PlotLayout l = RenderHeatMap(spec, test::OutputPath("points.png").string());
  const test::PngImage image = test::ReadPng(test::OutputPath("points.png").string());
  // The far points sit on the dark end of the ramp, drawn in cyan: clearly blue-green.
  for (int i = 1; i < 3; ++i) {
    const Eigen::Vector2d px = l.ToPixel(points(i, 0), points(i, 1));
    const int r = static_cast<int>(std::round(px(1))), c = static_cast<int>(std::round(px(0)));
    EXPECT_GT(image.green(r, c), 150) << i;
    EXPECT_GT(image.blue(r, c), 150) << i;
    EXPECT_LT(image.red(r, c), 100) << i;
  }
}

TEST(HeatMapScale, WindowFollowsTheMassNotEveryComponentsTails) {
  // Samples in [-1, 1]^2 and a fitted mixture whose minor broad component (2%) would stretch
  // mean +- 3.5 sd far beyond them.
  Mixture m(2);
  m.Add(0.98, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 0.25));
  m.Add(0.02, Gaussian(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 4.0));
  Eigen::MatrixX2d points(4, 2);
  points << -1, -1, 1, 1, -1, 1, 1, -1;
  const PlotRange old_range = MixtureRange(m);
  const PlotRange range = ExtentRange({&m}, points);
  EXPECT_GT(old_range.x_max - old_range.x_min, 3 * 2.0);  // the old window: > 3x the data
  EXPECT_LT(range.x_max - range.x_min, 2 * 2.0);
  EXPECT_LT(range.y_max - range.y_min, 2 * 2.0);
}

}  // namespace
}  // namespace dgmm
