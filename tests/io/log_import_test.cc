// Log import: streams joined by time, body-frame pose changes (planar and 6-DoF), terrain from
// attitude, episodes from gaps, binning, labels, units, delimiter and the invalid-row policy.
// The logs are written from closed-form trajectories so every expected value is known exactly.
#include "io/log_import.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <filesystem>
#include <functional>
#include <numbers>
#include <sstream>

#include "io/csv_reader.h"
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
  o.bins = 2;
  const SampleSet s = ImportLog(o, &summary);
  ASSERT_EQ(s.num_commands(), 2);
  EXPECT_EQ(s.size(), 2);
  EXPECT_TRUE(summary.warnings.empty());
  EXPECT_GT(s.commands(0, 0), s.commands(1, 0));  // the fast bin first (it came first)
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
