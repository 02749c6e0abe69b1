// Log import: streams joined by time, body-frame pose changes (planar and 6-DoF), terrain from
// attitude, episodes from gaps, binning, labels, units, delimiter and the invalid-row policy.
// The logs are written from closed-form trajectories so every expected value is known exactly.
#include "io/log_import.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <set>
#include <sstream>

#include "core/set_warnings.h"
#include "io/command_bins.h"
#include "io/csv_reader.h"
#include "io/log_files.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;
// Logged values are printed with 6 significant digits and interpolated linearly between rows
// of a trajectory that is linear in time: errors stay far below a millimetre / milliradian.
constexpr double kTol = 1e-4;

// Writes `rows` rows of f(t) for t = t0, t0 + dt, ... (one CSV line each after the header).
void WriteStream(const fs::path& path, const std::string& header, double t0, double t1, double dt,
                 const std::function<std::string(double)>& row, char delimiter = ',') {
  std::ostringstream out;
  out.precision(10);
  std::string h = header;
  if (delimiter != ',') std::replace(h.begin(), h.end(), ',', delimiter);
  out << h << "\n";
  for (double t = t0; t <= t1 + 1e-9; t += dt) {
    std::string r = row(t);
    if (delimiter != ',') std::replace(r.begin(), r.end(), ',', delimiter);
    out << r << "\n";
  }
  test::WriteText(path, out.str());
}

std::string Csv(std::initializer_list<double> values) {
  std::ostringstream out;
  out.precision(10);
  bool first = true;
  for (double v : values) {
    out << (first ? "" : ",") << v;
    first = false;
  }
  return out.str();
}

// Planar walk: from t = 0..2 s forward at 0.2 m/s along heading 170 deg, then 2..4 s turning in
// place at +0.9 rad/s (crossing +-180 deg). Pose in mm and degrees at 30 Hz; attitude (pitch 10
// deg, roll -5 deg) with a time column in ms at 50 Hz; commands with labels at 10 Hz.
struct PlanarLog {
  fs::path commands, pose, attitude;
};

double Heading(double t) { return 170 * kDeg + (t > 2 ? 0.9 * (t - 2) : 0.0); }
Eigen::Vector2d Position(double t) {
  const double s = 0.2 * std::min(t, 2.0);
  return {s * std::cos(170 * kDeg), s * std::sin(170 * kDeg)};
}

PlanarLog WritePlanarLog(const std::string& name, double gap_at = -1, char delimiter = ',') {
  const fs::path dir = test::TestDir() / name;
  fs::create_directories(dir);
  PlanarLog log{dir / "cmd.csv", dir / "pose.csv", dir / "imu.csv"};
  test::WriteText(log.commands, [&] {
    std::ostringstream out;
    out << (delimiter == ',' ? "time,mode,speed\n" : "time;mode;speed\n");
    for (int i = 0; i < 40; ++i) {
      const double t = 0.1 * i;
      const bool fwd = t < 2 - 1e-9;
      out << t << delimiter << (fwd ? "fwd" : "turn") << delimiter << (fwd ? "0.2" : "0") << "\n";
    }
    return out.str();
  }());
  auto skip = [gap_at](double t) { return gap_at > 0 && t > gap_at && t < gap_at + 1.0; };
  std::ostringstream pose;
  pose.precision(10);
  pose << "t,x_mm,y_mm,yaw_deg\n";
  for (int i = 0; i <= 120; ++i) {
    const double t = i / 30.0;
    if (skip(t)) continue;
    const double yaw = std::remainder(Heading(t), 2 * kPi);  // wrapped, as loggers do
    pose << Csv({t, 1000 * Position(t).x(), 1000 * Position(t).y(), yaw / kDeg}) << "\n";
  }
  std::string p = pose.str();
  if (delimiter != ',') std::replace(p.begin(), p.end(), ',', delimiter);
  test::WriteText(log.pose, p);
  WriteStream(log.attitude, "t_ms,pitch_deg,roll_deg", 0, 4000, 20,
              [](double t) { return Csv({t, 10.0, -5.0}); }, delimiter);
  return log;
}

LogImportOptions PlanarOptions(const PlanarLog& log) {
  LogImportOptions o;
  o.commands = {log.commands.string(), "time", {"mode"}};
  o.pose = {log.pose.string(), "t", {"x_mm", "y_mm", "yaw_deg"}};
  o.attitude = {log.attitude.string(), "t_ms", {"pitch_deg", "roll_deg"}};
  o.units = ParseUnits({"x_mm=mm", "y_mm=mm", "yaw_deg=deg", "t_ms=ms", "pitch_deg=deg",
                        "roll_deg=deg"});
  return o;
}

TEST(LogImport, PlanarSegmentsAtCommandChangesInTheBodyFrame) {
  const PlanarLog log = WritePlanarLog("planar");
  LogImportSummary summary;
  const SampleSet s = ImportLog(PlanarOptions(log), &summary);
  ASSERT_EQ(s.Validate(), "");
  ASSERT_EQ(s.size(), 2) << summary.BriefReport();
  EXPECT_EQ(s.command_labels, (std::vector<std::string>{"fwd", "turn"}));
  EXPECT_EQ(s.x_names, (std::vector<std::string>{"dx", "dy", "dyaw"}));
  // Forward 0.4 m along the heading: all of it on the body x axis.
  EXPECT_NEAR(s.x(0, 0), 0.4, kTol);
  EXPECT_NEAR(s.x(0, 1), 0.0, kTol);
  EXPECT_NEAR(s.x(0, 2), 0.0, kTol);
  // Turning in place for 2 s at 0.9 rad/s (1.8 rad), across the +-180 deg wrap: shortest arcs.
  EXPECT_NEAR(s.x(1, 2), 0.9 * 2, kTol);
  EXPECT_NEAR(s.x(1, 0), 0.0, kTol);
  // Terrain from the attitude stream in radians, in the order of the columns.
  EXPECT_NEAR(s.z(0, 0), 10 * kDeg, kTol);
  EXPECT_NEAR(s.z(0, 1), -5 * kDeg, kTol);
  EXPECT_EQ(s.x_units, (std::vector<std::string>{"m", "m", "rad"}));
  EXPECT_EQ(s.z_names, (std::vector<std::string>{"pitch", "roll"}));  // unit suffixes dropped
  EXPECT_EQ(summary.episodes, 1);
}

TEST(LogImport, FixedWindowsInsideEachCommandSegment) {
  const PlanarLog log = WritePlanarLog("windows");
  LogImportOptions o = PlanarOptions(log);
  o.window_s = 0.5;
  const SampleSet s = ImportLog(o);
  ASSERT_EQ(s.size(), 8);  // 4 windows in [0, 2), 4 in [2, 4]
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(s.x(i, 0), 0.1, kTol) << i;
  for (int i = 4; i < 8; ++i) EXPECT_NEAR(s.x(i, 2), 0.45, kTol) << i;
  for (int i = 0; i < 8; ++i) EXPECT_EQ(s.step[i], i);
}

TEST(LogImport, EpisodesFromLoggingGaps) {
  const PlanarLog log = WritePlanarLog("gap", /*gap_at=*/0.6);
  LogImportOptions o = PlanarOptions(log);
  o.window_s = 0.5;
  LogImportSummary summary;
  const SampleSet s = ImportLog(o, &summary);
  EXPECT_EQ(summary.episodes, 2) << summary.BriefReport();
  // [0, 0.6]: one window; [1.63, 2): too short for a window; [2, 4]: four.
  ASSERT_EQ(s.size(), 5);
  EXPECT_EQ(s.episode[0], 0);
  EXPECT_EQ(s.episode[1], 1);
  // An explicit gap longer than the pause keeps one episode.
  o.gap_s = 2.0;
  EXPECT_EQ(ImportLog(o, &summary).size(), 8);
  EXPECT_EQ(summary.episodes, 1);
}

TEST(LogImport, SemicolonDelimiter) {
  const PlanarLog log = WritePlanarLog("semicolon", -1, ';');
  LogImportOptions o = PlanarOptions(log);
  try {
    ImportLog(o);
    ADD_FAILURE() << "a semicolon file read with ',' should fail";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--delimiter"), std::string::npos) << e.what();
  }
  o.delimiter = ';';
  EXPECT_EQ(ImportLog(o).size(), 2);
}

TEST(LogImport, ContinuousCommandsBinned) {
  const PlanarLog log = WritePlanarLog("bins");
  // Replace the labels by noisy speeds around 0.2 and 0.
  std::ostringstream out;
  out << "time,speed\n";
  for (int i = 0; i < 40; ++i) {
    const double t = 0.1 * i, noise = 0.01 * std::sin(7.0 * i);
    out << t << "," << (t < 2 - 1e-9 ? 0.2 : 0.0) + noise << "\n";
  }
  test::WriteText(log.commands, out.str());
  LogImportOptions o = PlanarOptions(log);
  o.commands.columns = {"speed"};
  LogImportSummary summary;
  // Unbinned, every row is its own command: one sample per 0.1 s row and a warning.
  EXPECT_EQ(ImportLog(o, &summary).num_commands(), 40);
  ASSERT_EQ(summary.warnings.size(), 1u);
  EXPECT_NE(summary.warnings[0].find("--bins"), std::string::npos) << summary.warnings[0];
  o.bins.bins = 2;
  const SampleSet s = ImportLog(o, &summary);
  ASSERT_EQ(s.num_commands(), 2);
  EXPECT_EQ(s.size(), 2);
  EXPECT_TRUE(summary.warnings.empty());
  EXPECT_GT(s.commands(0, 0), s.commands(1, 0));  // the fast bin first (it came first)
}

// Continuous commands stay continuous: a speed ramp logged at 10 Hz (zero-order hold) next to
// the mode labels. Each 0.5 s window keeps the speed's time average as the first conditioning
// dimension of z (before pitch and roll), the modes still cut segments, and the summary reports
// the spread of the window averages and the variation inside windows.
TEST(LogImport, ContinuousCommandsKeptAsTimeAveragesInZ) {
  const PlanarLog log = WritePlanarLog("continuous");
  std::ostringstream out;
  out << "time,mode,speed\n";
  for (int i = 0; i < 40; ++i) {
    const double t = 0.1 * i;
    out << t << "," << (t < 2 - 1e-9 ? "fwd" : "turn") << "," << 0.05 * i << "\n";
  }
  test::WriteText(log.commands, out.str());
  LogImportOptions o = PlanarOptions(log);
  o.continuous_columns = {"speed"};
  o.window_s = 0.5;
  LogImportSummary summary;
  const SampleSet s = ImportLog(o, &summary);
  ASSERT_EQ(s.Validate(), "");
  ASSERT_EQ(s.size(), 8);
  EXPECT_EQ(s.num_commands(), 2);  // the modes; the speed is not a command
  ASSERT_EQ(s.terrain_dim(), 3);
  EXPECT_EQ(s.z_names, (std::vector<std::string>{"speed", "pitch", "roll"}));
  EXPECT_EQ(s.metadata.at("continuous_command_columns"), "1");
  // Window w covers [0.5 w, 0.5 (w + 1)): rows 5w .. 5w + 4 hold 0.1 s each, speed 0.05 i,
  // so the average is 0.05 (5w + 2).
  for (int w = 0; w < 8; ++w) {
    EXPECT_NEAR(s.z(w, 0), 0.05 * (5 * w + 2), 1e-9) << "window " << w;
    EXPECT_NEAR(s.z(w, 1), 10 * kDeg, kTol);
  }
  ASSERT_EQ(summary.continuous.size(), 1u);
  const auto& c = summary.continuous[0];
  EXPECT_NEAR(c.min, 0.1, 1e-9);
  EXPECT_NEAR(c.max, 0.05 * 37, 1e-9);
  // Inside a window: five equally held values 0.05 apart, standard deviation 0.05 sqrt(2).
  EXPECT_NEAR(c.median_within, 0.05 * std::sqrt(2.0), 1e-9);
  EXPECT_NE(summary.ContinuousReport().find("speed"), std::string::npos);

  std::string error;
  o.window_s = 0;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("--window"), std::string::npos) << error;
  o.window_s = 0.5;
  o.continuous_columns = {"mode"};
  o.commands.columns = {};
  try {
    ImportLog(o);
    ADD_FAILURE() << "a text column taken as a continuous command";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'mode'"), std::string::npos) << e.what();
  }
  o.continuous_columns = {"speed"};
  o.commands.columns = {"speed"};
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("also a --command-cols"), std::string::npos) << error;
}

TEST(LogImport, InvalidRowsRefusedWithLineOrDroppedAndCounted) {
  const PlanarLog log = WritePlanarLog("invalid");
  std::string text;
  {
    std::ifstream in(log.pose);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  // Line 6 (the fifth data row) loses its yaw.
  size_t pos = 0;
  for (int i = 0; i < 5; ++i) pos = text.find('\n', pos) + 1;
  const size_t eol = text.find('\n', pos);
  text.replace(pos, eol - pos, "0.1333,0,0,nan");
  test::WriteText(log.pose, text);
  LogImportOptions o = PlanarOptions(log);
  try {
    ImportLog(o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("pose.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("line 6"), std::string::npos) << m;
    EXPECT_NE(m.find("--drop-invalid"), std::string::npos) << m;
  }
  o.drop_invalid = true;
  LogImportSummary summary;
  EXPECT_EQ(ImportLog(o, &summary).size(), 2);
  EXPECT_EQ(summary.dropped_rows, 1);
  ASSERT_EQ(summary.dropped_report.size(), 1u);
  EXPECT_NE(summary.dropped_report[0].find("pose.csv"), std::string::npos);
}

// <roll, pitch, yaw> of a rotation, R = Rz Ry Rx.
Eigen::Vector3d Rpy(const Eigen::Matrix3d& r) {
  return {std::atan2(r(2, 1), r(2, 2)), std::asin(-r(2, 0)), std::atan2(r(1, 0), r(0, 0))};
}

TEST(LogImport, SixDofChangeInTheStartBodyFrame) {
  // Tilted start attitude R0; 0..2 s: 0.3 m/s along body x; 2..4 s: yaw about the body z axis
  // at 0.5 rad/s. Expected: (0.6, 0, 0, 0, 0, 0) and (0, 0, 0, 0, 0, ~1).
  const fs::path dir = test::TestDir() / "six";
  fs::create_directories(dir);
  const Eigen::Matrix3d r0 = (Eigen::AngleAxisd(2.5, Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitX()))
                                 .toRotationMatrix();
  std::ostringstream pose;
  pose.precision(12);
  pose << "t,x,y,z,roll,pitch,yaw\n";
  for (int i = 0; i <= 80; ++i) {
    const double t = i / 20.0;
    const Eigen::Vector3d p = r0 * Eigen::Vector3d(0.3 * std::min(t, 2.0), 0, 0);
    const Eigen::Matrix3d r =
        r0 * Eigen::AngleAxisd(t > 2 ? 0.5 * (t - 2) : 0.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d a = Rpy(r);
    pose << Csv({t, p.x(), p.y(), p.z(), a.x(), a.y(), a.z()}) << "\n";
  }
  test::WriteText(dir / "pose.csv", pose.str());
  test::WriteText(dir / "cmd.csv", "t,mode\n0,walk\n2,spin\n");
  LogImportOptions o;
  o.commands = {(dir / "cmd.csv").string(), "t", {"mode"}};
  o.pose = {(dir / "pose.csv").string(), "t", {"x", "y", "z", "roll", "pitch", "yaw"}};
  const SampleSet s = ImportLog(o);
  ASSERT_EQ(s.size(), 2);
  ASSERT_EQ(s.pose_dim(), 6);
  const Eigen::VectorXd walk = s.x.row(0), spin = s.x.row(1);
  Eigen::VectorXd expected_walk(6), expected_spin(6);
  expected_walk << 0.6, 0, 0, 0, 0, 0;
  expected_spin << 0, 0, 0, 0, 0, 1.0;
  EXPECT_LT((walk - expected_walk).norm(), kTol) << walk.transpose();
  EXPECT_LT((spin - expected_spin).norm(), kTol) << spin.transpose();
  EXPECT_EQ(s.terrain_dim(), 0);
}

TEST(LogImport, OptionsAndUnitsChecked) {
  const PlanarLog log = WritePlanarLog("options");
  LogImportOptions o = PlanarOptions(log);
  o.pose.columns = {"x_mm", "y_mm"};
  EXPECT_THROW(ImportLog(o), InputError);
  o = PlanarOptions(log);
  o.units["speeed"] = 1.0;  // a typo must not pass silently
  EXPECT_THROW(ImportLog(o), InputError);
  EXPECT_THROW(ParseUnits({"yaw=degrees"}), InputError);
  EXPECT_THROW(ParseUnits({"yaw"}), InputError);
  // Contradictory units for one column are refused (issue #24); the same unit twice is harmless.
  EXPECT_THROW(ParseUnits({"x=mm", "x=m"}), InputError);
  EXPECT_EQ(ParseUnits({"x=mm", "x=mm"}).at("x"), 1e-3);
  EXPECT_THROW(ParseDelimiter("::"), InputError);
  EXPECT_EQ(ParseDelimiter("tab"), '\t');
}

}  // namespace
}  // namespace dgmm

namespace dgmm {
namespace {

// A folder of short trials as a small vehicle's logger writes them: per trial a command file
// (one label, rows at 10 Hz from 0 to 2.9 s) and a pose file (30 Hz from 0 to 2.9667 s: one
// sample short of 3 s), driving straight at speed v(label) along heading h(trial).
struct TrialLog {
  fs::path dir;
  std::vector<std::string> labels;
};

double TrialSpeed(const std::string& label) {
  return label == "slow" ? 0.1 : label == "fast" ? 0.3 : 0.0;
}

TrialLog WriteTrialFolder(const std::string& name, int trials, double pose_end = 2.9667,
                          double speed_scale_per_trial = 0) {
  TrialLog log{test::TestDir() / name, {}};
  fs::create_directories(log.dir / "cmd");
  fs::create_directories(log.dir / "pose");
  const char* cycle[] = {"slow", "fast", "stop"};
  for (int i = 0; i < trials; ++i) {
    const std::string label = cycle[i % 3];
    log.labels.push_back(label);
    const double heading = 0.5 * i, v = TrialSpeed(label) * (1 + speed_scale_per_trial * i);
    char cmd[64], pose[64];
    std::snprintf(cmd, sizeof cmd, "cmd/trial_%d.csv", i + 1);
    std::snprintf(pose, sizeof pose, "pose/odom_%02d.csv", i + 1);
    std::ostringstream c, p;
    c << "t,action\n";
    for (int k = 0; k < 30; ++k) c << 0.1 * k << "," << label << "\n";
    test::WriteText(log.dir / cmd, c.str());
    p.precision(10);
    p << "t,x,y,yaw\n";
    for (int k = 0; k / 30.0 <= pose_end + 1e-9; ++k) {
      const double t = k / 30.0;
      p << t << "," << 5 + v * t * std::cos(heading) << "," << -2 + v * t * std::sin(heading) << ","
        << heading << "\n";
    }
    test::WriteText(log.dir / pose, p.str());
  }
  return log;
}

LogImportOptions TrialOptions(const TrialLog& log) {
  LogImportOptions o;
  o.commands = {(log.dir / "cmd").string(), "t", {"action"}};
  o.pose = {(log.dir / "pose" / "odom_*.csv").string(), "t", {"x", "y", "yaw"}};
  return o;
}

TEST(LogFiles, TrialKeysNeverSplitANumber) {
  EXPECT_EQ(TrialKeys({"a/cmd_07.csv", "a/cmd_10.csv"}), (std::vector<std::string>{"7", "10"}));
  EXPECT_EQ(TrialKeys({"trial_1.csv", "trial_10.csv", "trial_2.csv"}),
            (std::vector<std::string>{"1", "10", "2"}));
  EXPECT_EQ(TrialKeys({"runs/left/pose.csv", "runs/right/pose.csv"}),
            (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(TrialKeys({"only.csv"}), (std::vector<std::string>{""}));
}

TEST(LogFiles, PairTrialsByNameAndNameTheFileWithoutAPartner) {
  const auto trials = PairTrials({"c/cmd_2.csv", "c/cmd_10.csv", "c/cmd_1.csv"},
                                 {"p/pose_01.csv", "p/pose_02.csv", "p/pose_10.csv"}, {});
  ASSERT_EQ(trials.size(), 3u);
  EXPECT_EQ(trials[0].name, "1");
  EXPECT_EQ(trials[0].pose, "p/pose_01.csv");
  EXPECT_EQ(trials[2].commands, "c/cmd_10.csv");
  EXPECT_EQ(trials[2].pose, "p/pose_10.csv");
  try {
    PairTrials({"c/cmd_1.csv", "c/cmd_2.csv", "c/cmd_3.csv"}, {"p/pose_1.csv", "p/pose_2.csv"}, {});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cmd_3.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("--pose"), std::string::npos) << m;
    EXPECT_NE(m.find("trial '3'"), std::string::npos) << m;
  }
}

TEST(LogFiles, FoldersAndGlobsResolveToSortedCsvFiles) {
  const TrialLog log = WriteTrialFolder("resolve", 3);
  test::WriteText(log.dir / "cmd" / "notes.txt", "not a log\n");
  const auto folder = ResolveStreamFiles((log.dir / "cmd").string(), "--commands");
  EXPECT_EQ(folder.size(), 3u);
  EXPECT_TRUE(std::is_sorted(folder.begin(), folder.end()));
  EXPECT_EQ(ResolveStreamFiles((log.dir / "pose" / "odom_0[12].csv").string(), "--pose").size(),
            2u);
  EXPECT_THROW(ResolveStreamFiles((log.dir / "pose" / "nothing_*.csv").string(), "--pose"),
               InputError);
  fs::create_directories(log.dir / "empty");
  EXPECT_THROW(ResolveStreamFiles((log.dir / "empty").string(), "--pose"), InputError);
}

TEST(LogImport, FolderOfTrialsOneEpisodePerFile) {
  const TrialLog log = WriteTrialFolder("trials", 7);
  LogImportOptions o = TrialOptions(log);
  o.window_s = 3.0;
  LogImportSummary summary;
  const SampleSet s = ImportLog(o, &summary);
  // The pose ends one sample (1/30 s) short of the 3 s window: kept at the default tolerance
  // (half a pose interval at each end), one sample per trial.
  ASSERT_EQ(s.size(), 7) << summary.WindowReport();
  EXPECT_EQ(summary.trials, 7);
  EXPECT_EQ(summary.episodes, 7);
  EXPECT_NEAR(summary.time_tolerance_s, 0.5 / 30, 1e-9);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(s.episode[i], i);
    EXPECT_EQ(s.command_labels[s.command[i]], log.labels[i]);
    // Straight ahead in the body frame, over the 2.9667 s the pose covers.
    EXPECT_NEAR(s.x(i, 0), TrialSpeed(log.labels[i]) * (2.9 + 2.0 / 30), kTol) << i;
    EXPECT_NEAR(s.x(i, 1), 0.0, kTol);
  }
  EXPECT_EQ(s.num_commands(), 3);
  EXPECT_NE(summary.WindowReport().find("windows: 7 kept; dropped: none"), std::string::npos)
      << summary.WindowReport();
  // Without the tolerance (a tiny explicit one) every window is dropped, and the report says by
  // how little and which --time-tolerance keeps them.
  o.time_tolerance_s = 1e-4;
  try {
    ImportLog(o, &summary);
    FAIL() << "expected no samples";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("7 command segments shorter than 3 s"), std::string::npos) << m;
    const size_t at = m.find("--time-tolerance ");
    ASSERT_NE(at, std::string::npos) << m;
    // The suggested tolerance keeps them.
    o.time_tolerance_s = std::stod(m.substr(at + 17));
    EXPECT_EQ(ImportLog(o).size(), 7) << o.time_tolerance_s;
  }
}

TEST(LogImport, UnequalDurationsWarnOrBecomeRates) {
  // Trials of different lengths, one sample per trial (no window): durations differ.
  const TrialLog log = WriteTrialFolder("durations", 6);
  test::WriteText(log.dir / "pose" / "odom_02.csv", [] {
    std::ostringstream p;
    p << "t,x,y,yaw\n";
    for (int k = 0; k <= 45; ++k) p << k / 30.0 << "," << 5 + 0.3 * k / 30.0 << ",-2,0\n";  // 1.5 s
    return p.str();
  }());
  LogImportOptions o = TrialOptions(log);
  LogImportSummary summary;
  SampleSet s = ImportLog(o, &summary);
  ASSERT_EQ(s.size(), 6);
  EXPECT_NEAR(summary.min_window_s, 1.5, 1e-9);
  ASSERT_EQ(summary.warnings.size(), 1u);
  EXPECT_NE(summary.warnings[0].find("--per-second"), std::string::npos) << summary.warnings[0];
  EXPECT_EQ(KeptWarnings(s), summary.warnings) << "the set keeps them for the analyses that read it";
  o.per_second = true;
  s = ImportLog(o, &summary);
  EXPECT_TRUE(summary.warnings.empty());
  EXPECT_TRUE(KeptWarnings(s).empty());
  EXPECT_EQ(s.x_units[0], "m/s");
  for (int i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(s.x(i, 0), TrialSpeed(log.labels[i]), kTol) << i;  // speeds, whatever the length
  }
}

TEST(LogImport, EpisodeColumnSplitsTrialsAndIdsStayDistinctAcrossFiles) {
  const TrialLog log = WriteTrialFolder("episode_col", 2);
  for (int i = 1; i <= 2; ++i) {  // each file: episode 0 for 1.5 s, then episode 1
    std::ostringstream c;
    c << "t,action,run\n";
    for (int k = 0; k < 30; ++k)
      c << 0.1 * k << "," << log.labels[i - 1] << "," << (k < 15 ? 0 : 1) << "\n";
    test::WriteText(log.dir / "cmd" / ("trial_" + std::to_string(i) + ".csv"), c.str());
  }
  LogImportOptions o = TrialOptions(log);
  o.episode_column = "run";
  const SampleSet s = ImportLog(o);
  std::set<int> ids(s.episode.data(), s.episode.data() + s.size());
  EXPECT_EQ(ids.size(), 4u);  // (file 1, 0), (file 1, 1), (file 2, 0), (file 2, 1)
}

TEST(LogImport, QuantileBinsWithStopsOnTheirOwn) {
  const PlanarLog log = WritePlanarLog("quantile_bins");
  // Speeds: 0.05 .. 0.25 in the first 2 s (slow and fast halves), exactly 0 (stopped) after.
  std::ostringstream out;
  out << "time,speed\n";
  for (int i = 0; i < 40; ++i)
    out << 0.1 * i << "," << (i < 10 ? 0.05 : i < 20 ? 0.25 : 0.0) << "\n";
  test::WriteText(log.commands, out.str());
  LogImportOptions o = PlanarOptions(log);
  o.commands.columns = {"speed"};
  o.bins.bins = 2;
  SampleSet s = ImportLog(o);
  // Two bins of the moving rows, and the stop rows as their own command: three commands.
  ASSERT_EQ(s.num_commands(), 3) << s.command_labels.size();
  EXPECT_EQ(s.command_labels, (std::vector<std::string>{"0.05", "0.25", "0"}));
  // Equal widths over [0, 0.25] with the stops inside would have put 0 and 0.05 together.
  o.bins.zero_is_own_bin = false;
  o.bins.rule = CommandBinOptions::Rule::kWidth;
  s = ImportLog(o);
  EXPECT_EQ(s.num_commands(), 2);
  // Explicit edges.
  o.bins = CommandBinOptions{};
  o.bins.edges = {0.1};
  s = ImportLog(o);
  EXPECT_EQ(s.command_labels, (std::vector<std::string>{"0.05", "0.25", "0"}));
  o.bins.bins = 3;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("--bin-edges"), std::string::npos) << error;
}

TEST(CommandBins, QuantilesKeepEqualValuesTogetherAndLabelsOccur) {
  CommandBinOptions o;
  o.bins = 3;
  const std::vector<double> v = {0, 0, 0.1, 0.1, 0.1, 0.1, 0.2, 0.3, 0.4, 0.5, 0, -0.2};
  const std::vector<double> b = BinCommandValues(v, o);
  ASSERT_EQ(b.size(), v.size());
  EXPECT_EQ(b[0], 0.0);
  EXPECT_EQ(b[10], 0.0);
  for (int i = 2; i < 6; ++i) EXPECT_EQ(b[i], b[2]);  // the run of 0.1 is not split
  std::set<double> labels(b.begin(), b.end());
  EXPECT_LE(labels.size(), 4u);  // three bins of moving values and the stop
  for (double l : labels) {
    EXPECT_TRUE(l == 0.0 || std::find(v.begin(), v.end(), l) != v.end() ||
                std::abs(l - 0.35) < 1e-12 || std::abs(l - 0.45) < 1e-12)
        << l;
  }
}

}  // namespace
}  // namespace dgmm
