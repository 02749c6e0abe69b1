// Bad input: every case gives a non-zero exit (not a crash), exactly one line on stderr naming
// the file and the problem, and leaves no output (nor temporary) file behind.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>

#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = MakeTempDir(std::string("bad-input-") + info->name());
  }
  std::string P(const std::string& name) const { return (dir_ / name).string(); }
  void Write(const std::string& name, const std::string& text) const {
    std::ofstream(P(name)) << text;
  }
  // A sample set imported from CSV text (must succeed).
  void Import(const std::string& csv_text, const std::string& out,
              const std::vector<std::string>& extra) const {
    Write(out + ".csv", csv_text);
    std::vector<std::string> args = {"import", P(out + ".csv"), "-o", P(out)};
    args.insert(args.end(), extra.begin(), extra.end());
    RunResult r = RunDgmm(args);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  // Runs args; expects a clean failure mentioning every needle, and `output` not created.
  void ExpectCleanFailure(const std::vector<std::string>& args,
                          const std::vector<std::string>& needles,
                          const std::string& output = "") const {
    RunResult r = RunDgmm(args);
    SCOPED_TRACE(r.err);
    EXPECT_GE(r.exit_code, 1) << "must fail (and -1 would be a crash)";
    EXPECT_EQ(CountLines(r.err), 1) << "one line on stderr";
    for (const auto& needle : needles) {
      EXPECT_NE(r.err.find(needle), std::string::npos) << "missing '" << needle << "'";
    }
    if (!output.empty()) EXPECT_FALSE(fs::exists(output)) << output;
    for (const auto& e : fs::directory_iterator(dir_)) {
      EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
    }
  }
  std::vector<std::string> ImportArgs(const std::string& csv) const {
    return {"import", P(csv), "-o", P("out.h5"), "--pose-cols", "x,y"};
  }
  fs::path dir_;
};

TEST_F(BadInput, NanInCsv) {
  Write("nan.csv", "x,y\n1,2\n3,NaN\n");
  ExpectCleanFailure(ImportArgs("nan.csv"), {"nan.csv", "line 3", "column 'y'", "NaN"},
                     P("out.h5"));
}

TEST_F(BadInput, InfInCsv) {
  Write("inf.csv", "x,y\n1,2\ninf,4\n");
  ExpectCleanFailure(ImportArgs("inf.csv"), {"inf.csv", "line 3", "column 'x'", "infinite"},
                     P("out.h5"));
}

TEST_F(BadInput, RaggedRows) {
  Write("ragged.csv", "x,y\n1,2\n3,4,5\n");
  ExpectCleanFailure(ImportArgs("ragged.csv"), {"ragged.csv", "line 3", "3 fields, expected 2"},
                     P("out.h5"));
}

TEST_F(BadInput, UnknownColumnNames) {
  Write("cols.csv", "x,y\n1,2\n");
  ExpectCleanFailure({"import", P("cols.csv"), "-o", P("out.h5"), "--pose-cols", "x,speed"},
                     {"cols.csv", "column 'speed'", "not found", "have: x, y"}, P("out.h5"));
}

TEST_F(BadInput, EmptyFile) {
  Write("empty.csv", "");
  ExpectCleanFailure(ImportArgs("empty.csv"), {"empty.csv", "empty file"}, P("out.h5"));
}

TEST_F(BadInput, UnknownCommandInScoredSet) {
  Import("c,x,y\n0,1,2\n0,2,3\n0,1.5,2.5\n", "train.h5",
         {"--command-cols", "c", "--pose-cols", "x,y"});
  Import("c,x,y\n0,1,2\n1,2,3\n", "test.h5", {"--command-cols", "c", "--pose-cols", "x,y"});
  ASSERT_EQ(RunDgmm({"fit", P("train.h5"), "-o", P("m.h5")}).exit_code, 0);
  ExpectCleanFailure({"score", P("m.h5"), P("test.h5"), "--json"},
                     {"test.h5", "unknown command '1'"});
}

TEST_F(BadInput, DimensionsDifferBetweenModelAndSet) {
  Import("x,y\n1,2\n2,3\n1.5,2.5\n", "two.h5", {"--pose-cols", "x,y"});
  Import("x,y\n1,2\n2,3\n", "one.h5", {"--pose-cols", "x"});
  ASSERT_EQ(RunDgmm({"fit", P("two.h5"), "-o", P("m.h5")}).exit_code, 0);
  ExpectCleanFailure({"score", P("m.h5"), P("one.h5")}, {"one.h5", "dimensions"});
}

TEST_F(BadInput, KNotPositiveOrNan) {
  Import("x,y\n1,2\n2,3\n", "set.h5", {"--pose-cols", "x,y"});
  for (const char* k : {"0", "-1", "nan", "inf"}) {
    SCOPED_TRACE(k);
    ExpectCleanFailure({"fit", P("set.h5"), "-o", P("m.h5"), "--k", k},
                       {"set.h5", "--k", "must be a finite number > 0"}, P("m.h5"));
  }
}

TEST_F(BadInput, UnwritableOutputPath) {
  Import("x,y\n1,2\n2,3\n", "set.h5", {"--pose-cols", "x,y"});
  const std::string out = P("no-such-folder") + "/m.h5";
  ExpectCleanFailure({"fit", P("set.h5"), "-o", out}, {out, "does not exist"}, out);
  ExpectCleanFailure({"import", P("set.h5.csv"), "-o", out, "--pose-cols", "x,y"},
                     {out, "does not exist"}, out);
  ExpectCleanFailure({"fit", P("set.h5"), "-o", dir_.string()}, {"is a folder"});
}

TEST_F(BadInput, TruncatedHdf5) {
  Write("big.csv", [] {
    std::string s = "x,y\n";
    for (int i = 0; i < 5000; ++i) s += std::to_string(i % 17) + "," + std::to_string(i % 5) + "\n";
    return s;
  }());
  ASSERT_EQ(RunDgmm({"import", P("big.csv"), "-o", P("set.h5"), "--pose-cols", "x,y"}).exit_code,
            0);
  fs::resize_file(P("set.h5"), fs::file_size(P("set.h5")) / 2);
  ExpectCleanFailure({"fit", P("set.h5"), "-o", P("m.h5")}, {"set.h5", "truncated"}, P("m.h5"));
  ExpectCleanFailure({"info", P("set.h5")}, {"set.h5", "truncated"});
}

TEST_F(BadInput, ForeignHdf5) {
  {
    hid_t f = H5Fcreate(P("foreign.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hsize_t dims[2] = {10, 2};
    hid_t space = H5Screate_simple(2, dims, nullptr);
    hid_t d = H5Dcreate2(f, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  ExpectCleanFailure({"fit", P("foreign.h5"), "-o", P("m.h5")},
                     {"foreign.h5", "dgmm_format", "not written by dgmm"}, P("m.h5"));
  ExpectCleanFailure({"info", P("foreign.h5"), "--json"}, {"foreign.h5", "dgmm_format"});
  ExpectCleanFailure({"export", P("foreign.h5"), "-o", P("m.json")}, {"foreign.h5"}, P("m.json"));
}

TEST_F(BadInput, TextFileAsHdf5) {
  Write("text.h5", "x,y\n1,2\n");
  ExpectCleanFailure({"info", P("text.h5")}, {"text.h5", "not an HDF5 file"});
  ExpectCleanFailure({"score", P("text.h5"), P("text.h5")}, {"text.h5", "not an HDF5 file"});
}

TEST_F(BadInput, ModelWhereASetIsExpected) {
  Import("x,y\n1,2\n2,3\n", "set.h5", {"--pose-cols", "x,y"});
  ASSERT_EQ(RunDgmm({"fit", P("set.h5"), "-o", P("m.h5")}).exit_code, 0);
  ExpectCleanFailure({"fit", P("m.h5"), "-o", P("m2.h5")}, {"m.h5", "expected a sample set"},
                     P("m2.h5"));
  ExpectCleanFailure({"score", P("set.h5"), P("set.h5")}, {"set.h5", "expected a model"});
}

// Found by scripts/bad_input_battery.py (issue #13).
TEST_F(BadInput, TuneRefusesMoreFoldsThanSamples) {
  Import("c,x,y\n0,1,2\n0,2,3\n0,1.5,2.5\n1,1,1\n1,2,2\n1,3,1\n", "set.h5",
         {"--command-cols", "c", "--pose-cols", "x,y"});
  // Ran for minutes on empty folds before.
  ExpectCleanFailure({"tune", P("set.h5"), "--folds", "100000", "--without-terrain"},
                     {"set.h5", "--folds", "at most 3 folds"});
  ExpectCleanFailure({"tune", P("set.h5"), "--folds", "1", "--without-terrain"},
                     {"set.h5", "--folds", ">= 2"});
}

TEST_F(BadInput, MessagesNameTheFlagOrWord) {
  Import("x,y\n1,2\n2,3\n1.5,2.5\n", "set.h5", {"--pose-cols", "x,y"});
  ExpectCleanFailure({"frobnicate", P("set.h5")}, {"unknown command 'frobnicate'"});
  ExpectCleanFailure({"--quiet", "frobnicate"}, {"unknown command 'frobnicate'"});
  ExpectCleanFailure({"--quiet"}, {"subcommand is required"});
  ExpectCleanFailure({"tune-k", P("set.h5"), "--frobnicate"}, {"--frobnicate"});
  EXPECT_EQ(RunDgmm({"tune-k", P("set.h5"), "--frobnicate"}).err.find("unknown command"),
            std::string::npos);
  ExpectCleanFailure({"em", P("set.h5"), "-o", P("m.h5"), "--components", "0"},
                     {"set.h5", "--components"}, P("m.h5"));
  ExpectCleanFailure({"em", P("set.h5"), "-o", P("m.h5"), "--reg-covar", "-1"},
                     {"set.h5", "--reg-covar"}, P("m.h5"));
  // (--quiet: the 3-sample set also draws a warning about too few samples.)
  ExpectCleanFailure({"--quiet", "tune", P("set.h5"), "--folds", "2", "--k-min", "0",
                      "--without-terrain"},
                     {"set.h5", "--k-min"});
  ExpectCleanFailure({"--quiet", "cv", P("set.h5"), "--folds", "2", "--em-max-components", "0"},
                     {"set.h5", "--em-max-components"});
  ExpectCleanFailure({"simulate", "-o", P("sim.h5"), "--executions", "0"}, {"--executions"},
                     P("sim.h5"));
  // -1 was the internal "not given" value and so silently meant the default cap.
  ExpectCleanFailure({"fit", P("set.h5"), "-o", P("m.h5"), "--max-components", "-1"},
                     {"set.h5", "--max-components", "expected 1 to 1e9"}, P("m.h5"));
}

TEST_F(BadInput, Sim2RealNamesTheSetWhoseDimensionsDiffer) {
  Import("x,y\n1,2\n2,3\n1.5,2.5\n", "set.h5", {"--pose-cols", "x,y"});
  ExpectCleanFailure({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(),
                      "--real", P("set.h5"), "-o", P("report")},
                     {"set.h5", "2 pose and 0 terrain dimensions", "(6 and 2)"}, P("report"));
}

TEST_F(BadInput, InitCovOfTheWrongLength) {
  Import("x,y\n1,2\n2,3\n", "set.h5", {"--pose-cols", "x,y"});
  ExpectCleanFailure({"fit", P("set.h5"), "-o", P("m.h5"), "--init-cov", "1,2,3"},
                     {"set.h5", "--init-cov", "3 values for 2 dimensions"}, P("m.h5"));
  ExpectCleanFailure({"fit", P("set.h5"), "-o", P("m.h5"), "--init-cov", "-1"}, {"set.h5"},
                     P("m.h5"));
}

}  // namespace
}  // namespace dgmm::test
