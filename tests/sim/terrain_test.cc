// Generation and description of the ground's height field (lib/sim/terrain.h).
#include "sim/terrain.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"

namespace dgmm::sim {
namespace {

TerrainDescription Rough(double rms, double correlation, std::uint64_t seed = 1) {
  TerrainDescription t;
  t.seed = seed;
  t.half_size_m = 1.0;
  t.resolution_m = 0.02;
  t.rough.rms_height_m = rms;
  t.rough.correlation_length_m = correlation;
  return t;
}

// Correlation of heights one grid point apart along x.
double LagOneCorrelation(const HeightField& f) {
  const int n = f.size();
  double mean = 0;
  for (float h : f.heights()) mean += h;
  mean /= f.heights().size();
  double num = 0, den = 0;
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c + 1 < n; ++c) {
      num += (f.heights()[r * n + c] - mean) * (f.heights()[r * n + c + 1] - mean);
      den += (f.heights()[r * n + c] - mean) * (f.heights()[r * n + c] - mean);
    }
  }
  return num / den;
}

TEST(TerrainTest, SameSeedSameGroundOtherSeedOtherGround) {
  const HeightField a = HeightField::Generate(Rough(0.02, 0.1, 7));
  EXPECT_EQ(a.heights(), HeightField::Generate(Rough(0.02, 0.1, 7)).heights());
  EXPECT_NE(a.heights(), HeightField::Generate(Rough(0.02, 0.1, 8)).heights());
  EXPECT_EQ(a.size(), 101);
}

TEST(TerrainTest, RoughGroundHasTheRequestedRmsAndCorrelation) {
  const HeightField smooth = HeightField::Generate(Rough(0.02, 0.2));
  const HeightField grainy = HeightField::Generate(Rough(0.02, 0.04));
  EXPECT_NEAR(smooth.RmsHeight(), 0.02, 1e-6);
  EXPECT_NEAR(grainy.RmsHeight(), 0.02, 1e-6);
  // Smoothing over 10 vs 2 grid points: neighbours agree far more on the smooth ground.
  EXPECT_GT(LagOneCorrelation(smooth), 0.98);
  EXPECT_LT(LagOneCorrelation(grainy), LagOneCorrelation(smooth) - 0.03);
}

TEST(TerrainTest, StonesAreCapsOfTheGivenHeight) {
  TerrainDescription t;
  t.half_size_m = 1.0;
  t.resolution_m = 0.01;
  t.stones = {0.03, 0.05, 20};
  const HeightField f = HeightField::Generate(t);
  EXPECT_EQ(f.min_m(), 0.0);
  EXPECT_LE(f.max_m(), 0.03 + 1e-7);
  EXPECT_GT(f.max_m(), 0.029);  // some stone centre lies within half a grid step of a grid point
  int covered = 0;
  for (float h : f.heights()) covered += h > 0;
  const double share = covered / static_cast<double>(f.heights().size());
  const double expected = 1 - std::exp(-20 * M_PI * 0.05 * 0.05);  // Poisson cover of the discs
  EXPECT_NEAR(share, expected, 0.05);
}

TEST(TerrainTest, StepsAreAlternateTerraces) {
  TerrainDescription t;
  t.half_size_m = 1.0;
  t.resolution_m = 0.02;
  t.steps = {0.05, 0.4};
  const HeightField f = HeightField::Generate(t);
  EXPECT_DOUBLE_EQ(f.At(0.2, 0.3), 0.0);   // [0, 0.4): terrace 0
  EXPECT_NEAR(f.At(0.6, -0.7), 0.05, 1e-7);  // [0.4, 0.8): terrace 1
  EXPECT_NEAR(f.At(-0.2, 0.0), 0.05, 1e-7);  // [-0.4, 0): terrace -1
}

TEST(TerrainTest, HeightIsBilinearBetweenGridPointsAndClampedOutside) {
  const HeightField f = HeightField::Generate(Rough(0.02, 0.1));
  const int n = f.size();
  const auto H = [&](int r, int c) { return static_cast<double>(f.heights()[r * n + c]); };
  const double x0 = -1 + 40 * 0.02, y0 = -1 + 55 * 0.02;
  EXPECT_NEAR(f.At(x0, y0), H(55, 40), 1e-12);
  EXPECT_NEAR(f.At(x0 + 0.01, y0), 0.5 * (H(55, 40) + H(55, 41)), 1e-9);
  EXPECT_NEAR(f.At(x0 + 0.01, y0 + 0.01), 0.25 * (H(55, 40) + H(55, 41) + H(56, 40) + H(56, 41)), 1e-9);
  EXPECT_NEAR(f.At(-5, -5), H(0, 0), 1e-12);
  EXPECT_NEAR(f.At(5, 5), H(n - 1, n - 1), 1e-12);
}

TEST(TerrainTest, JsonRoundTripsAndRefusesBadFields) {
  TerrainDescription t = Rough(0.015, 0.12, 42);
  t.stones = {0.02, 0.06, 3};
  const TerrainDescription back = TerrainFromJson(TerrainToJson(t), "t.json");
  EXPECT_EQ(TerrainToJson(back), TerrainToJson(t));
  EXPECT_EQ(HeightField::Generate(back).heights(), HeightField::Generate(t).heights());

  const auto error = [](const std::string& text) {
    try {
      TerrainFromJson(text, "t.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error(R"({"rough": {"rms": 0.1}})").find("terrain.rough.rms: unknown key"), std::string::npos);
  EXPECT_NE(error(R"({"stones": {"height_m": -1}})").find("terrain.stones.height_m"), std::string::npos);
  EXPECT_NE(error(R"({"seed": 1.5})").find("terrain.seed"), std::string::npos);
  EXPECT_NE(error(R"({"half_size_m": 500, "resolution_m": 1, "stones": {"height_m": 0.1, "radius_m": 1, "per_m2": 10}})")
                .find("stones on the ground"),
            std::string::npos);
  EXPECT_NE(error(R"({"half_size_m": 100, "resolution_m": 0.01})").find("grid points"), std::string::npos);
  EXPECT_NE(error(R"({"rough": {"rms_height_m": 0.1, "correlation_length_m": 0.001}})").find("correlation_length_m"),
            std::string::npos);
}

TEST(TerrainTest, FootReliefIsTheSpreadAboutTheFeetsPlane) {
  std::vector<Eigen::Vector3d> feet;
  for (int i = 0; i < 6; ++i) {
    const double x = std::cos(i), y = std::sin(2 * i);
    feet.emplace_back(x, y, 0.1 + 0.2 * x - 0.3 * y);  // a tilted plane: no relief
  }
  EXPECT_NEAR(FootRelief(feet), 0.0, 1e-12);
  feet[0].z() += 0.06;  // one foot on a stone
  const double relief = FootRelief(feet);
  EXPECT_GT(relief, 0.01);
  EXPECT_LT(relief, 0.06);
  EXPECT_EQ(FootRelief({feet[0], feet[1], feet[2]}), 0.0);  // three points always fit a plane
}

TEST(TerrainTest, SensedDescriptorsAreNamedOnce) {
  EXPECT_EQ(TerrainFromJson(R"({"sensed": ["height_ahead", "foot_relief"]})", "t").sensed.size(), 2u);
  EXPECT_THROW(TerrainFromJson(R"({"sensed": ["lidar"]})", "t"), InputError);
  EXPECT_THROW(TerrainFromJson(R"({"sensed": ["foot_relief", "foot_relief"]})", "t"), InputError);
}

TEST(TerrainTest, WarnsWhenTheGroundIsOffTheRobotsScale) {
  TerrainDescription t = Rough(0.005, 0.1);
  EXPECT_TRUE(TerrainScaleWarnings(t, 0.14, 0.02).empty());
  t.steps = {0.1, 0.4};
  ASSERT_EQ(TerrainScaleWarnings(t, 0.14, 0.02).size(), 1u);
  EXPECT_NE(TerrainScaleWarnings(t, 0.14, 0.02)[0].find("stance height"), std::string::npos);
  t.steps = {};
  t.resolution_m = 0.05;
  EXPECT_TRUE(TerrainScaleWarnings(t, 0.14, 0.02).empty());
  EXPECT_EQ(TerrainScaleWarnings(t, 0.14, 0.005).size(), 1u);  // coarse facets under small feet
  t.resolution_m = 0.01;
  EXPECT_EQ(TerrainScaleWarnings(t, 0.14, 0.02).size(), 1u);   // many contacts per foot
}

}  // namespace
}  // namespace dgmm::sim
