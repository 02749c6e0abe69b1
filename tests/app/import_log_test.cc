// End-to-end: `dgmm import-log` on the shipped multi-rate log (its refusal of the tracker's nan
// rows, --drop-invalid, warnings), `dgmm import` with text labels, `;`, units and dropped rows,
// and the comma convention of `render --labels`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/sample_set_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> ShippedLogArgs(const fs::path& out) {
  const std::string logs = SourcePath("datasets/logs").string();
  return {"import-log", "--commands", logs + "/commands.csv", "--command-cols", "mode", "--pose",
          logs + "/pose.csv", "--pose-cols", "x_mm,y_mm,yaw_deg", "--attitude",
          logs + "/imu.csv", "--attitude-time", "t_ms", "--terrain-cols", "pitch_deg,roll_deg",
          "--units", "x_mm=mm,y_mm=mm,yaw_deg=deg,t_ms=ms,pitch_deg=deg,roll_deg=deg",
          "--window", "1.5", "-o", out.string()};
}

TEST(ImportLogCommand, ShippedLogRefusedAtTheFirstNanThenImportedWithDropInvalid) {
  const fs::path dir = MakeTempDir("import_log_shipped");
  auto args = ShippedLogArgs(dir / "walk.h5");
  RunResult r = RunDgmm(args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pose.csv: line "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--drop-invalid"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "walk.h5"));
  args.push_back("--drop-invalid");
  args.push_back("--json");
  r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("dropped"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["episodes"], 6);  // six sessions between logging gaps
  EXPECT_GT(j["dropped"]["invalid_rows"].get<int>(), 0);
  const SampleSet set = ReadSampleSet((dir / "walk.h5").string());
  EXPECT_EQ(set.num_commands(), 7);
  EXPECT_EQ(set.x_names, (std::vector<std::string>{"dx", "dy", "dyaw"}));
  EXPECT_EQ(set.z_names, (std::vector<std::string>{"pitch", "roll"}));
  // Every command ran for 1.5 s at |0.5| of a 0.12 m stride per 0.25 s stance: |dx|, |dy| < 0.6 m.
  EXPECT_LT(set.x.leftCols(2).cwiseAbs().maxCoeff(), 0.6);
}

TEST(ImportLogCommand, ContinuousCommandsWarnWithoutBins) {
  const fs::path dir = MakeTempDir("import_log_bins");
  auto args = ShippedLogArgs(dir / "walk.h5");
  args[4] = "v_long,v_turn";
  args.push_back("--drop-invalid");
  // Unbinned, every 0.1 s row is its own command: no 1.5 s window fits, and the error says why.
  RunResult r = RunDgmm(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--bins"), std::string::npos) << r.err;
  args.insert(args.end(), {"--bins", "3"});
  r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("--bins"), std::string::npos) << r.err;
  // forward/back, turns and the rest: at most 3 x 3 binned commands.
  EXPECT_LE(ReadSampleSet((dir / "walk.h5").string()).num_commands(), 9);
}

TEST(ImportCommand, TextLabelsSemicolonsUnitsAndDroppedRows) {
  const fs::path dir = MakeTempDir("import_labels");
  std::ofstream(dir / "walk.csv") << "speed;dx_mm;yaw_deg\n"
                                     "fast;100;10\n"
                                     "slow;50;nan\n"
                                     "slow;40;5\n"
                                     "fast;110;;\n";
  std::vector<std::string> args = {"import", (dir / "walk.csv").string(), "-o",
                                   (dir / "walk.h5").string(), "--command-cols", "speed",
                                   "--pose-cols", "dx_mm,yaw_deg", "--units",
                                   "dx_mm=mm,yaw_deg=deg"};
  RunResult r = RunDgmm(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--delimiter"), std::string::npos) << r.err;  // the hint for ';' files
  args.insert(args.end(), {"--delimiter", ";"});
  r = RunDgmm(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("line 3"), std::string::npos) << r.err;
  args.push_back("--drop-invalid");
  r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("dropped 2 invalid rows"), std::string::npos) << r.err;
  const SampleSet set = ReadSampleSet((dir / "walk.h5").string());
  ASSERT_EQ(set.size(), 2);
  EXPECT_EQ(set.command_labels, (std::vector<std::string>{"fast", "slow"}));
  EXPECT_NEAR(set.x(0, 0), 0.1, 1e-12);
  EXPECT_NEAR(set.x(1, 1), 5 * 3.14159265358979 / 180, 1e-9);
}

TEST(ListOptions, RenderLabelsTakeOneCommaSeparatedValue) {
  const fs::path dir = MakeTempDir("render_labels");
  // Two space-separated labels: the second would be read as a model file.
  RunResult r = RunDgmm({"render", "--diff", "a.h5", "b.h5", "--labels", "A", "B", "-o",
                         (dir / "x.png").string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--labels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("comma"), std::string::npos) << r.err;
  // One value without a comma (it used to become label A silently).
  r = RunDgmm({"render", "--diff", "a.h5", "b.h5", "--labels", "A", "-o", (dir / "x.png").string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--labels"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dgmm::test

namespace dgmm::test {
namespace {

// The bundled public log (datasets/f1tenth, CC0): a folder per trial, headerless CSVs, no time
// column (40 Hz), 41 three-second trials of 15 commands; the pose ends one sample short of a
// whole second after the first command row.
std::vector<std::string> CarArgs(const std::string& out) {
  const std::string root = SourcePath("datasets/f1tenth").string();
  return {"import-log",
          "--commands",
          root + "/measurement_*/input.csv",
          "--command-cols",
          "1,2",
          "--pose",
          root + "/measurement_*/trajectory.csv",
          "--pose-cols",
          "1,2,3",
          "--no-header",
          "--rate",
          "40",
          "--window",
          "1",
          "-o",
          out};
}

TEST(ImportLogCommand, FolderOfTrialsFromAPublicLog) {
  const fs::path dir = MakeTempDir("import_log_trials");
  std::vector<std::string> args = CarArgs((dir / "car.h5").string());
  args.push_back("--json");
  const RunResult r = RunDgmm(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["trials"], 41);
  EXPECT_EQ(j["episodes"], 41);
  EXPECT_EQ(j["commands"].size(), 15u);
  // Three 1-s windows per trial (the first one a sample short, kept by the tolerance): 123.
  EXPECT_EQ(j["windows_kept"], 123);
  EXPECT_EQ(j["dropped"]["short_segments"], 44);  // the 0.025 s rows before each command
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"];
  const SampleSet set = ReadSampleSet((dir / "car.h5").string());
  EXPECT_EQ(set.size(), 123);
  EXPECT_EQ(set.terrain_dim(), 0);
  // Text output: the kept/dropped line.
  const RunResult text = RunDgmm(CarArgs((dir / "car2.h5").string()));
  EXPECT_NE(text.out.find("windows: 123 kept; dropped: 44 command segments shorter than 1 s"),
            std::string::npos)
      << text.out;
}

TEST(ImportLogCommand, ContradictoryOptionsAreRefused) {
  const fs::path dir = MakeTempDir("import_log_contradictions");
  const std::string out = (dir / "car.h5").string();
  std::vector<std::vector<std::string>> cases;
  cases.push_back(CarArgs(out));
  cases.back().insert(cases.back().end(), {"--time-col", "t"});  // a rate and a time column
  cases.push_back(CarArgs(out));
  cases.back().insert(cases.back().end(), {"--units", "1=mm,1=m"});  // two units for one column
  cases.push_back(CarArgs(out));
  cases.back().insert(cases.back().end(), {"--bins", "3", "--bin-edges", "0.1"});
  cases.push_back(CarArgs(out));
  cases.back().insert(cases.back().end(), {"--terrain-cols", "1"});  // no attitude stream
  for (const auto& args : cases) {
    const RunResult r = RunDgmm(args);
    EXPECT_EQ(r.exit_code, 2) << args.back() << ": " << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace dgmm::test
