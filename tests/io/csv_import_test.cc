// CSV import: parsing, column selection, commands as distinct tuples, standardisation, errors.
#include "io/csv_import.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

const char kWalk[] =
    "\"fwd\",turn,dx,dy,pitch,episode\r\n"
    "0.5,0,0.10,0.01,0.02,3\r\n"
    "0.5,0,0.12,0.00,0.03,3\r\n"
    "\r\n"
    "0,+1,0.00,0.05,-0.01,4\n"
    "0.5,0.0,0.11,-0.02,0.00,4\n"
    "0,1,0.01,0.06,0.01,3\n";

// The error message ImportCsv throws for this CSV text (fails the test when none).
std::string ImportError(const std::string& text, CsvImportOptions options) {
  const fs::path path = test::TestDir() / "bad.csv";
  test::WriteText(path, text);
  try {
    ImportCsv(path, options);
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("bad.csv"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    return message;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

CsvImportOptions PoseXY() {
  CsvImportOptions o;
  o.pose_columns = {"x", "y"};
  return o;
}

TEST(CsvImport, ColumnsChosenByNameInTheGivenOrder) {
  const fs::path path = test::TestDir() / "walk.csv";
  test::WriteText(path, kWalk);
  CsvImportOptions o;
  o.command_columns = {"fwd", "turn"};
  o.pose_columns = {"dy", "dx"};
  o.terrain_columns = {"pitch"};
  o.episode_column = "episode";
  o.source = "real";
  const SampleSet s = ImportCsv(path, o);
  ASSERT_EQ(s.Validate(), "");
  ASSERT_EQ(s.size(), 5);  // the blank line is skipped
  EXPECT_EQ(s.x_names, (std::vector<std::string>{"dy", "dx"}));
  EXPECT_EQ(s.z_names, (std::vector<std::string>{"pitch"}));
  EXPECT_EQ(s.x(0, 0), 0.01);
  EXPECT_EQ(s.x(0, 1), 0.10);
  EXPECT_EQ(s.z(2, 0), -0.01);
  // Commands: distinct (fwd, turn) tuples in first-seen order; "0.0" equals "0", "+1" equals 1.
  ASSERT_EQ(s.num_commands(), 2);
  EXPECT_EQ(s.command_dim_names, o.command_columns);
  EXPECT_EQ(s.command_labels, (std::vector<std::string>{"0.5,0", "0,+1"}));
  EXPECT_EQ(s.commands(1, 1), 1.0);
  EXPECT_EQ(s.command, (Eigen::VectorXi(5) << 0, 0, 1, 0, 1).finished());
  // Step = order within the episode, counted across interleaved episodes.
  EXPECT_EQ(s.episode, (Eigen::VectorXi(5) << 3, 3, 4, 4, 3).finished());
  EXPECT_EQ(s.step, (Eigen::VectorXi(5) << 0, 1, 0, 1, 2).finished());
  EXPECT_EQ(s.source, "real");
}

TEST(CsvImport, NoCommandColumnIsOneCommand) {
  CsvImportOptions o;
  o.pose_columns = {"eruptions", "waiting"};
  const SampleSet s = ImportCsv(std::string(DGMM_SOURCE_DIR) + "/datasets/old_faithful.csv", o);
  ASSERT_EQ(s.Validate(), "");
  EXPECT_EQ(s.size(), 272);
  EXPECT_EQ(s.num_commands(), 1);
  EXPECT_EQ(s.commands.cols(), 0);
  EXPECT_TRUE((s.command.array() == 0).all());
  EXPECT_EQ(s.x(0, 0), 3.6);  // first data row: 3.6,79
  EXPECT_EQ(s.x(0, 1), 79.0);
  EXPECT_FALSE(s.has_sequence());
  EXPECT_TRUE(s.transform.empty());
}

TEST(CsvImport, StandardisationStoresTheTransformBackToRawUnits) {
  const fs::path path = test::TestDir() / "walk.csv";
  test::WriteText(path, kWalk);
  CsvImportOptions o;
  o.pose_columns = {"dx", "dy"};
  o.terrain_columns = {"pitch"};
  const SampleSet raw = ImportCsv(path, o);
  o.standardize = true;
  const SampleSet s = ImportCsv(path, o);
  ASSERT_EQ(s.Validate(), "");
  ASSERT_EQ(s.transform.offset.size(), 3);
  constexpr double kTol = 1e-12;  // a few roundings of values of order 1
  for (int j = 0; j < 3; ++j) {
    const Eigen::VectorXd col = j < 2 ? Eigen::VectorXd(s.x.col(j)) : Eigen::VectorXd(s.z.col(0));
    const Eigen::VectorXd raw_col =
        j < 2 ? Eigen::VectorXd(raw.x.col(j)) : Eigen::VectorXd(raw.z.col(0));
    EXPECT_NEAR(col.mean(), 0.0, kTol);
    EXPECT_NEAR(std::sqrt(col.squaredNorm() / col.size()), 1.0, kTol);  // population sd
    const Eigen::VectorXd back =
        (s.transform.offset[j] + s.transform.scale[j] * col.array()).matrix();
    EXPECT_LT((back - raw_col).cwiseAbs().maxCoeff(), kTol);
  }
}

TEST(CsvImport, ConstantColumnKeepsScaleOne) {
  const fs::path path = test::TestDir() / "c.csv";
  test::WriteText(path, "x,y\n1,5\n2,5\n3,5\n");
  CsvImportOptions o = PoseXY();
  o.standardize = true;
  const SampleSet s = ImportCsv(path, o);
  EXPECT_EQ(s.transform.scale[1], 1.0);
  EXPECT_EQ(s.transform.offset[1], 5.0);
  EXPECT_TRUE((s.x.col(1).array() == 0).all());
}

TEST(CsvImport, ErrorsNameTheLineAndColumn) {
  EXPECT_NE(ImportError("", PoseXY()).find("empty file"), std::string::npos);
  EXPECT_NE(ImportError("\n  \n", PoseXY()).find("empty file"), std::string::npos);
  EXPECT_NE(ImportError("x,y\n", PoseXY()).find("no data rows"), std::string::npos);
  const std::string ragged = ImportError("x,y\n1,2\n3\n", PoseXY());
  EXPECT_NE(ragged.find("line 3"), std::string::npos) << ragged;
  EXPECT_NE(ragged.find("ragged"), std::string::npos) << ragged;
  CsvImportOptions unknown = PoseXY();
  unknown.pose_columns = {"x", "speed"};
  const std::string columns = ImportError("x,y,t\n1,2,3\n", unknown);
  EXPECT_NE(columns.find("column 'speed'"), std::string::npos) << columns;
  EXPECT_NE(columns.find("have: x, y, t"), std::string::npos) << columns;
  const std::string nan = ImportError("x,y\n1,2\n3,nan\n", PoseXY());
  EXPECT_NE(nan.find("line 3, column 'y'"), std::string::npos) << nan;
  EXPECT_NE(nan.find("NaN"), std::string::npos) << nan;
  const std::string inf = ImportError("x,y\n-inf,2\n", PoseXY());
  EXPECT_NE(inf.find("line 2, column 'x'"), std::string::npos) << inf;
  EXPECT_NE(inf.find("infinite"), std::string::npos) << inf;
  EXPECT_NE(ImportError("x,y\n1e999,2\n", PoseXY()).find("infinite"), std::string::npos);
  const std::string text = ImportError("x,y\n1,2\n1,abc\n", PoseXY());
  EXPECT_NE(text.find("'abc' is not a number"), std::string::npos) << text;
  EXPECT_NE(ImportError("x,y\n1,\n", PoseXY()).find("empty value"), std::string::npos);
  CsvImportOptions episode = PoseXY();
  episode.episode_column = "e";
  EXPECT_NE(ImportError("x,y,e\n1,2,0.5\n", episode).find("integer"), std::string::npos);
  CsvImportOptions twice = PoseXY();
  twice.terrain_columns = {"x"};
  EXPECT_NE(ImportError("x,y\n1,2\n", twice).find("selected twice"), std::string::npos);
}

TEST(CsvImport, ByteOrderMarkAndQuotedFieldsAreHandled) {
  const fs::path path = test::TestDir() / "bom.csv";
  test::WriteText(path, "\xEF\xBB\xBFx,\"y, in m\"\n1,\" 2.5 \"\n");
  CsvImportOptions o;
  o.pose_columns = {"x", "y, in m"};
  const SampleSet s = ImportCsv(path, o);
  ASSERT_EQ(s.size(), 1);
  EXPECT_EQ(s.x(0, 1), 2.5);
}

TEST(CsvImport, MissingFileIsAnInputError) {
  EXPECT_THROW(ImportCsv("/no/such/file.csv", PoseXY()), InputError);
}

}  // namespace
}  // namespace dgmm

namespace dgmm {
namespace {

// Issue #13: underflow reads as 0, CR-only files are read line by line, a huge cell is echoed
// cut short, a folder is named as a folder, a huge episode id says what is expected.
TEST(CsvImportMessages, UnderflowCrOnlyHugeCellsAndFolders) {
  const fs::path dir = test::TestDir();
  test::WriteText(dir / "tiny.csv", "x,y\n1e-400,0." + std::string(400, '0') + "1\n2,3\n");
  const SampleSet tiny = ImportCsv(dir / "tiny.csv", PoseXY());
  EXPECT_EQ(tiny.x(0, 0), 0.0);
  EXPECT_EQ(tiny.x(0, 1), 0.0);

  test::WriteText(dir / "cr.csv", "x,y\r1,2\r3,4\r5,6\r");
  EXPECT_EQ(ImportCsv(dir / "cr.csv", PoseXY()).size(), 3);
  test::WriteText(dir / "cr_bad.csv", "x,y\r1,2\r3,oops\r5,6\r");
  try {
    ImportCsv(dir / "cr_bad.csv", PoseXY());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }

  const std::string message = ImportError("x,y\n1," + std::string(100000, 'a') + "\n", PoseXY());
  EXPECT_LT(message.size(), 300u) << message.substr(0, 300);
  EXPECT_NE(message.find("100000 characters"), std::string::npos) << message.substr(0, 300);

  try {
    ImportCsv(dir.string(), PoseXY());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  CsvImportOptions episodes = PoseXY();
  episodes.episode_column = "e";
  EXPECT_NE(ImportError("e,x,y\n1e12,1,2\n", episodes).find("expected an integer between"),
            std::string::npos);
}

}  // namespace
}  // namespace dgmm
