// End-to-end: `dgmm simulate` writes a readable, reproducible set and fails cleanly.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "io/sample_set_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Quick(const fs::path& out, const std::string& seed) {
  return {"simulate", "--placements", "3", "--executions", "2", "--seed", seed, "-o", out.string()};
}

TEST(SimulateAppTest, WritesAReproducibleSet) {
  const fs::path dir = MakeTempDir("simulate_ok");
  auto args = Quick(dir / "a.h5", "5");
  args.push_back("--json");
  const RunResult a = RunDgmm(args);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_NE(a.out.find("\"simulated_seconds_per_wall_second\""), std::string::npos) << a.out;
  EXPECT_NE(a.out.find("\"samples\": 6"), std::string::npos) << a.out;
  ASSERT_EQ(RunDgmm(Quick(dir / "b.h5", "5")).exit_code, 0);
  ASSERT_EQ(RunDgmm(Quick(dir / "c.h5", "6")).exit_code, 0);
  const SampleSet sa = ReadSampleSet((dir / "a.h5").string());
  const SampleSet sb = ReadSampleSet((dir / "b.h5").string());
  const SampleSet sc = ReadSampleSet((dir / "c.h5").string());
  EXPECT_EQ(sa.size(), 6);
  EXPECT_EQ(sa.source, "sim");
  EXPECT_EQ(sa.x, sb.x);
  EXPECT_EQ(sa.z, sb.z);
  EXPECT_EQ(sa.metadata, sb.metadata);
  EXPECT_NE(sa.x, sc.x);
  EXPECT_EQ(sa.metadata.at("seed"), "5");
  fs::remove_all(dir);
}

TEST(SimulateAppTest, UsesTheConfigFile) {
  const fs::path dir = MakeTempDir("simulate_config");
  std::ofstream(dir / "cfg.json") << R"({"slope_deg": 0, "noise": {"imu_pitch_sd_rad": 0, "imu_roll_sd_rad": 0}})";
  auto args = Quick(dir / "flat.h5", "1");
  args.insert(args.end(), {"--config", (dir / "cfg.json").string()});
  const RunResult r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const SampleSet set = ReadSampleSet((dir / "flat.h5").string());
  const double kFlatRad = 0.05;  // standing on flat ground, no IMU noise
  EXPECT_LT(set.z.cwiseAbs().maxCoeff(), kFlatRad);
  EXPECT_NE(set.metadata.at("sim_config").find("\"slope_deg\": 0"), std::string::npos);
  fs::remove_all(dir);
}

// A user's first steps with their own MJCF: draft a config (robot-draft), then record with it.
TEST(SimulateAppTest, ADraftedConfigRecordsAsWritten) {
  const fs::path dir = MakeTempDir("simulate_draft");
  const std::string config = (dir / "hexapod_draft.json").string();
  const RunResult draft = RunDgmm({"robot-draft", SourcePath("datasets/robots/hexapod.xml").string(), "-o", config});
  ASSERT_EQ(draft.exit_code, 0) << draft.err;
  EXPECT_NE(draft.err.find("6 legs, torso torso, floor floor"), std::string::npos) << draft.err;
  EXPECT_NE(draft.err.find("the draft binds"), std::string::npos) << draft.err;
  auto args = Quick(dir / "draft.h5", "1");
  args.insert(args.end(), {"--config", config});
  const RunResult r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadSampleSet((dir / "draft.h5").string()).size(), 6);
  // No model, no draft: one line naming the file, nothing written.
  const std::string missing = (dir / "missing.xml").string();
  const RunResult bad = RunDgmm({"robot-draft", missing, "-o", (dir / "bad.json").string()});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find(missing), std::string::npos) << bad.err;
  EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad.json"));
  // The draft never overwrites the model it reads.
  fs::copy_file(SourcePath("datasets/robots/hexapod.xml"), dir / "robot.xml");
  const RunResult same = RunDgmm({"robot-draft", (dir / "robot.xml").string(), "-o", (dir / "robot.xml").string()});
  EXPECT_NE(same.exit_code, 0);
  EXPECT_EQ(CountLines(same.err), 1) << same.err;
  EXPECT_NE(std::ifstream(dir / "robot.xml").get(), '{');
  fs::remove_all(dir);
}

TEST(SimulateAppTest, FailsCleanlyOnBadInput) {
  const fs::path dir = MakeTempDir("simulate_bad");
  std::ofstream(dir / "bad.json") << R"({"slope_deg": 18, "frictoin": {}})";
  const std::vector<std::vector<std::string>> cases = {
      {"simulate", "--protocol", "paper-999", "-o", (dir / "x.h5").string()},
      {"simulate", "--config", (dir / "absent.json").string(), "-o", (dir / "x.h5").string()},
      {"simulate", "--config", (dir / "bad.json").string(), "-o", (dir / "x.h5").string()},
      {"simulate", "--placements", "-2", "-o", (dir / "x.h5").string()},
      {"simulate", "--placements", "1", "-o", (dir / "no_such_dir" / "x.h5").string()},
      {"simulate"},
  };
  for (const auto& args : cases) {
    const RunResult r = RunDgmm(args);
    EXPECT_GT(r.exit_code, 0) << args.back() << ": " << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x.h5"));
  const RunResult printed = RunDgmm({"simulate", "--print-config"});
  EXPECT_EQ(printed.exit_code, 0);
  EXPECT_NE(printed.out.find("\"leg_gain\""), std::string::npos);
  fs::remove_all(dir);
}

// Pictures need an X display; without one the command says so in one line and writes nothing.
TEST(SimulateAppTest, PicturesFailCleanlyWithoutADisplay) {
  const fs::path dir = MakeTempDir("sim_pictures");
  const RunResult r = RunDgmm({"sim-pictures", "-o", dir.string()}, {"DISPLAY=:987654"});
  EXPECT_GT(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("display"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir));
  const RunResult missing = RunDgmm({"sim-pictures", "-o", (dir / "absent").string()});
  EXPECT_GT(missing.exit_code, 0);
  EXPECT_EQ(CountLines(missing.err), 1) << missing.err;
  fs::remove_all(dir);
}

// Width of a PNG from its IHDR chunk (big-endian at byte 16), 0 when not a PNG.
unsigned PngWidth(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), sizeof(header));
  if (!in || header[1] != 'P' || header[2] != 'N' || header[3] != 'G') return 0;
  return (header[16] << 24) | (header[17] << 16) | (header[18] << 8) | header[19];
}

// With a virtual display the three pictures are drawn (skipped where xvfb-run is missing).
TEST(SimulateAppTest, PicturesUnderXvfb) {
  if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0) GTEST_SKIP() << "no xvfb-run";
  const char* exe = std::getenv("DGMM_EXE");
  ASSERT_NE(exe, nullptr);
  const fs::path dir = MakeTempDir("sim_pictures_xvfb");
  // scripts/with-display.sh: $DISPLAY when set (scripts/test.sh starts one), else xvfb-run -a.
  const std::string command = std::string(DGMM_SOURCE_DIR) + "/scripts/with-display.sh " + exe +
                              " sim-pictures --executions 1 -o " +
                              dir.string() + " > /dev/null 2>&1";
  int status = std::system(command.c_str());
  if (status != 0) status = std::system(command.c_str());  // Xvfb start-up is occasionally flaky
  ASSERT_EQ(status, 0);
  EXPECT_EQ(PngWidth(dir / "trajectories_flat.png"), 800u);
  EXPECT_EQ(PngWidth(dir / "trajectories_slope.png"), 800u);
  EXPECT_EQ(PngWidth(dir / "snapshots_slope.png"), 5u * 360u);  // five panels side by side
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dgmm::test
