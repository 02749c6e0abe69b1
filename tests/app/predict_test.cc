// `dgmm predict` end to end on a model fitted from a shipped set.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

TEST(PredictCommand, PredictsASequenceAndWritesJson) {
  const auto dir = MakeTempDir("predict_cmd");
  const std::string model = (dir / "m.h5").string(), out = (dir / "p.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/scorpion_sim_390.h5").string(), "-o", model, "--k", "0.7",
                     "--seed", "1"}).exit_code, 0);
  const RunResult r = RunDgmm({"predict", model, "--commands", "+0.5,0,0*3;0,0,+0.5", "--terrain", "pitch=0.1,roll=0",
                               "--trajectories", "300", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out);
  const auto j = nlohmann::json::parse(in);
  ASSERT_EQ(j["steps"].size(), 4u);
  const double x3 = j["steps"][2]["mean"][0], x1 = j["steps"][0]["mean"][0];
  EXPECT_GT(x1, 0.1);                  // forward commands move forward
  EXPECT_NEAR(x3, 3 * x1, 0.3 * x1);   // three of them, about three times as far
  EXPECT_GT(double(j["steps"][3]["mean"][3]), double(j["steps"][2]["mean"][3]) + 0.1);  // then a left turn
  EXPECT_EQ(RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--trajectories", "300", "-o", out}).exit_code, 0);
}

TEST(PredictCommand, AnUnknownCommandIsOneLineAndWritesNothing) {
  const auto dir = MakeTempDir("predict_bad");
  const std::string model = (dir / "m.h5").string(), out = (dir / "p.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/scorpion_sim_390.h5").string(), "-o", model}).exit_code, 0);
  const RunResult r = RunDgmm({"predict", model, "--commands", "fly", "-o", out});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("fly"), std::string::npos) << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_NE(RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--terrain", "slope=3"}).exit_code, 0);
  EXPECT_NE(RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--terrain", "pitch=0.1x,roll=0"}).exit_code, 0);
  const RunResult miscount =
      RunDgmm({"predict", model, "--commands", "+0.5,0,0*3", "--terrain", "pitch=0,roll=0;pitch=0.1,roll=0"});
  EXPECT_NE(miscount.exit_code, 0);
  EXPECT_NE(miscount.err.find("2 terrains for 3 commands"), std::string::npos) << miscount.err;
}

TEST(PredictCommand, TerrainPerStepConditionsEachStepOnItsOwn) {
  const auto dir = MakeTempDir("predict_steps");
  const std::string model = (dir / "m.h5").string(), a = (dir / "a.json").string(), b = (dir / "b.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/scorpion_sim_390.h5").string(), "-o", model}).exit_code, 0);
  // Steps 1 and 2 on the same terrain as the constant run, step 2 of the other on steep ground.
  ASSERT_EQ(RunDgmm({"--quiet", "predict", model, "--commands", "+0.5,0,0*2", "--terrain", "pitch=0,roll=0",
                     "--trajectories", "500", "-o", a}).exit_code, 0);
  ASSERT_EQ(RunDgmm({"--quiet", "predict", model, "--commands", "+0.5,0,0*2", "--terrain",
                     "pitch=0,roll=0;pitch=0.3,roll=0", "--trajectories", "500", "-o", b}).exit_code, 0);
  std::ifstream ia(a), ib(b);
  const auto ja = nlohmann::json::parse(ia), jb = nlohmann::json::parse(ib);
  EXPECT_EQ(ja["steps"][0]["mean"], jb["steps"][0]["mean"]);  // the same first step (same seed and terrain)
  EXPECT_NE(ja["steps"][1]["mean"], jb["steps"][1]["mean"]);
}

// --persistence estimates how deviations carry over from the set's episodes (the 390 set: 78
// placements of 5 repeats), prints it per pose dimension and records it; a missing set is one
// line and writes nothing.
TEST(PredictCommand, PersistenceIsEstimatedFromASetsEpisodes) {
  const auto dir = MakeTempDir("predict_persist");
  const std::string set = SourcePath("datasets/scorpion_sim_390.h5").string();
  const std::string model = (dir / "m.h5").string(), out = (dir / "p.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", set, "-o", model}).exit_code, 0);
  const RunResult r = RunDgmm({"predict", model, "--commands", "+0.5,0,0*4", "--persistence", set, "--trajectories",
                               "200", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("persistence from " + set + " (78 episodes; 312 pairs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dyaw     a = "), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;  // the model's own set
  // A set the model does not describe (the rough ground for a model of the plane) is warned about.
  const RunResult other = RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--persistence",
                                   SourcePath("datasets/rough_ground_1660.h5").string(), "--trajectories", "50"});
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_NE(other.err.find("describes another robot or ground"), std::string::npos) << other.err;
  EXPECT_EQ(CountLines(other.err), 1) << other.err;
  std::ifstream in(out);
  EXPECT_EQ(nlohmann::json::parse(in)["persistence_from"], set);
  const std::string missing = (dir / "none.h5").string(), out2 = (dir / "q.json").string();
  const RunResult bad = RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--persistence", missing, "-o", out2});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("none.h5"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(out2));
}

// --calibrate widens each step's regions by the factor its held-out episodes give (printed per
// horizon and applied to the JSON's r2); steps beyond the episodes' length take the last factor with
// a warning; a missing set is one line and writes nothing.
TEST(PredictCommand, RegionsAreCalibratedOnHeldOutEpisodes) {
  const auto dir = MakeTempDir("predict_calibrate");
  const std::string set = SourcePath("datasets/scorpion_sim_390.h5").string();
  const std::string model = (dir / "m.h5").string(), plain = (dir / "p.json").string(), cal = (dir / "c.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", set, "-o", model}).exit_code, 0);
  const std::vector<std::string> predict = {"predict", model, "--commands", "+0.5,0,0*6", "--terrain", "pitch=0.1,roll=0",
                                            "--trajectories", "300"};
  std::vector<std::string> with = predict, without = predict;
  with.insert(with.end(), {"--calibrate", set, "-o", cal});
  without.insert(without.end(), {"-o", plain});
  ASSERT_EQ(RunDgmm(without).exit_code, 0);
  const RunResult r = RunDgmm(with);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("regions calibrated on " + set), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after  5 commands"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("after  6 commands"), std::string::npos) << r.out;  // its episodes have 5 steps
  EXPECT_NE(r.err.find("calibrate 5 commands"), std::string::npos) << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  std::ifstream ip(plain), ic(cal);
  const auto jp = nlohmann::json::parse(ip), jc = nlohmann::json::parse(ic);
  EXPECT_EQ(jc["calibrated_from"], set);
  for (int k = 0; k < 6; ++k) {
    ASSERT_EQ(jc["steps"][k]["regions"].size(), 2u);
    EXPECT_EQ(jc["steps"][k]["regions"][1]["share"], 0.9);
    EXPECT_EQ(jc["steps"][k]["mean"], jp["steps"][k]["mean"]) << "the same trajectories";
    const double ratio = double(jc["steps"][k]["regions"][1]["r2"]) / double(jp["steps"][k]["regions"][1]["r2"]);
    char printed[64], factor[32];
    std::snprintf(printed, sizeof printed, "after %2d commands", std::min(k + 1, 5));
    std::snprintf(factor, sizeof factor, "x%.2f  (", ratio);
    const auto at = r.out.find(printed);
    ASSERT_NE(at, std::string::npos) << printed;
    EXPECT_NE(r.out.substr(at, 60).find(factor), std::string::npos) << r.out.substr(at, 60) << " " << factor;
  }
  const std::string missing = (dir / "none.h5").string(), out2 = (dir / "q.json").string();
  const RunResult bad = RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--calibrate", missing, "-o", out2});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("none.h5"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(out2));
}

// A conditioning value far outside the training data (the 390 set's pitch stays within about
// +-0.35 rad on its 18-degree slope) draws one warning line naming it; one inside does not.
TEST(PredictCommand, WarnsWhenTheTerrainOrCommandIsOutsideTheTrainingData) {
  const auto dir = MakeTempDir("predict_thin");
  const std::string model = (dir / "m.h5").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/scorpion_sim_390.h5").string(), "-o", model}).exit_code, 0);
  const RunResult inside = RunDgmm({"predict", model, "--commands", "+0.5,0,0", "--terrain", "pitch=0.3,roll=0",
                                    "--trajectories", "50"});
  ASSERT_EQ(inside.exit_code, 0) << inside.err;
  EXPECT_EQ(inside.err.find("extrapolates"), std::string::npos) << inside.err;
  const RunResult outside = RunDgmm({"predict", model, "--commands", "+0.5,0,0*2", "--terrain",
                                     "pitch=0.3,roll=0;pitch=1.2,roll=0", "--trajectories", "50"});
  ASSERT_EQ(outside.exit_code, 0) << outside.err;
  EXPECT_NE(outside.err.find("step 2: pitch=1.2,roll=0 is outside"), std::string::npos) << outside.err;
  EXPECT_EQ(outside.err.find("step 1:"), std::string::npos) << outside.err;
}

// Issue #25: a model of continuous commands (simulated, stored as cmd_long, cmd_lat, cmd_turn in
// z) is driven by command values per step, merged with the terrain: turning left then right.
// A model of 24 simulated placements of continuous commands, fitted with the defaults: its path.
std::string ContinuousModel(const std::filesystem::path& dir) {
  const std::string set = (dir / "c.h5").string(), model = (dir / "m.h5").string();
  EXPECT_EQ(RunDgmm({"--quiet", "simulate", "--protocol", "continuous", "--placements", "24", "--seed", "3", "-o",
                     set}).exit_code, 0);
  EXPECT_EQ(RunDgmm({"--quiet", "fit", set, "-o", model}).exit_code, 0);
  return model;
}

TEST(PredictCommand, ContinuousCommandValuesPerStep) {
  const auto dir = MakeTempDir("predict_continuous");
  const std::string model = ContinuousModel(dir), out = (dir / "p.json").string();
  const RunResult r = RunDgmm({"predict", model, "--commands", "velocity*2", "--command-values",
                               "cmd_long=0.3,cmd_lat=0,cmd_turn=0.4;cmd_long=0.3,cmd_lat=0,cmd_turn=-0.4",
                               "--terrain", "pitch=0.05,roll=0", "--trajectories", "300", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out);
  const auto j = nlohmann::json::parse(in);
  const double yaw1 = j["steps"][0]["mean"][3], yaw2 = j["steps"][1]["mean"][3];
  EXPECT_GT(yaw1, 0.1);          // turned left
  EXPECT_LT(yaw2, yaw1 - 0.1);   // then right
  const RunResult missing = RunDgmm({"predict", model, "--commands", "velocity", "--command-values", "cmd_long=0.3"});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.err.find("missing cmd_lat,cmd_turn,pitch,roll"), std::string::npos) << missing.err;
  EXPECT_EQ(CountLines(missing.err), 1) << missing.err;
}

// Command values with --ground: each step's values as given, pitch and roll read off the slope
// under each trajectory: the same velocity carries the robot further facing downhill than uphill.
TEST(PredictCommand, ContinuousCommandValuesOnTheGround) {
  const auto dir = MakeTempDir("predict_continuous_ground");
  const std::string model = ContinuousModel(dir), slope = (dir / "slope.json").string();
  std::ofstream(slope) << R"({"slope_deg": 18})";
  auto distance = [&](const std::string& heading) {
    const std::string out = (dir / ("p" + heading + ".json")).string();
    const RunResult r = RunDgmm({"--quiet", "predict", model, "--commands", "velocity*3", "--command-values",
                                 "cmd_long=0.3,cmd_lat=0,cmd_turn=0", "--ground", slope, "--start", "0,0," + heading,
                                 "--trajectories", "300", "-o", out});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(out);
    const auto mean = nlohmann::json::parse(in)["steps"][2]["mean"];
    return std::hypot(double(mean[0]), double(mean[1]));
  };
  EXPECT_LT(distance("0"), distance("3.14159"));
  const RunResult missing = RunDgmm({"predict", model, "--commands", "velocity", "--command-values", "cmd_long=0.3",
                                     "--ground", slope});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.err.find("cmd_lat"), std::string::npos) << missing.err;
  EXPECT_EQ(CountLines(missing.err), 1) << missing.err;
}

TEST(PredictCommand, TheFigureIsATrajectoryFanOrACleanErrorWithoutADisplay) {
  const auto dir = MakeTempDir("predict_fig");
  const std::string model = (dir / "m.h5").string(), png = (dir / "fan.png").string(), out = (dir / "p.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/scorpion_sim_390.h5").string(), "-o", model}).exit_code, 0);
  const std::vector<std::string> args = {"predict", model, "--commands", "+0.5,0,0*2;0,0,+0.5", "--trajectories", "200",
                                         "--figure", png, "-o", out};
  const RunResult none = RunDgmm(args, {"DISPLAY=:4711"});
  EXPECT_EQ(none.exit_code, 1) << none.err;
  EXPECT_NE(none.err.find("cannot open an X display"), std::string::npos) << none.err;
  EXPECT_EQ(CountLines(none.err), 1) << none.err;
  EXPECT_FALSE(std::filesystem::exists(png));
  EXPECT_FALSE(std::filesystem::exists(out)) << "no partial output";
  const RunResult r = RunUnderXvfb(args, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(std::filesystem::file_size(png), 5000u);
  EXPECT_TRUE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace dgmm::test

namespace dgmm::test {
namespace {

// Issue #26: --ground with a terrain block conditions every trajectory on the height field under
// it: on the shipped rough ground the prediction differs from the bare 10-degree plane's, and a
// start off the field is warned about.
TEST(PredictCommand, TheGroundsHeightFieldConditionsEachTrajectory) {
  const auto dir = MakeTempDir("predict_field");
  const std::string model = (dir / "m.h5").string(), rough = (dir / "rough.json").string(),
                    plane = (dir / "plane.json").string(), plane_cfg = (dir / "plane_cfg.json").string();
  ASSERT_EQ(RunDgmm({"--quiet", "fit", SourcePath("datasets/rough_ground_1660.h5").string(), "-o", model, "--seed", "1"})
                .exit_code, 0);
  std::ofstream(plane_cfg) << "{\"slope_deg\": 10}\n";
  const std::vector<std::string> walk = {"predict", model, "--commands", "+0.5,0,0*6", "--trajectories", "400",
                                         "--start", "-0.4,0.2,0.3"};
  auto with = [&](std::vector<std::string> args, const std::string& config, const std::string& out) {
    args.insert(args.end(), {"--ground", config, "-o", out});
    return RunDgmm(args);
  };
  const RunResult r = with(walk, SourcePath("datasets/robots/rough_ground.json").string(), rough);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("leave the height field"), std::string::npos) << r.err;
  ASSERT_EQ(with(walk, plane_cfg, plane).exit_code, 0);
  std::ifstream ir(rough), ip(plane);
  const auto jr = nlohmann::json::parse(ir), jp = nlohmann::json::parse(ip);
  EXPECT_NE(jr["steps"][5]["mean"], jp["steps"][5]["mean"]);
  std::vector<std::string> edge = walk;
  edge[edge.size() - 1] = "2.9,0,0";
  const RunResult off = with(edge, SourcePath("datasets/robots/rough_ground.json").string(), rough);
  ASSERT_EQ(off.exit_code, 0) << off.err;
  EXPECT_NE(off.err.find("leave the height field"), std::string::npos) << off.err;
}

}  // namespace
}  // namespace dgmm::test
