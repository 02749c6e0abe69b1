// End-to-end tests of `dgmm em` (app/em.cc) against the built binary on the bundled Old Faithful
// data: the model it writes, its summary, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "io/model_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;
using test::RunDgmm;

// Summary figures are printed by nlohmann::json with full precision; the score command re-reads
// the model from HDF5 and sums in another order.
constexpr double kSameLikelihood = 1e-9;

class EmCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::MakeTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    set_ = (dir_ / "faithful.h5").string();
    const auto r = RunDgmm({"import", test::SourcePath("datasets/old_faithful.csv").string(), "-o",
                            set_, "--pose-cols", "eruptions,waiting"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Expects a one-line error, a non-zero exit and no output file.
  void ExpectRejected(const std::vector<std::string>& args, const std::string& output) {
    const auto r = RunDgmm(args);
    EXPECT_NE(r.exit_code, 0) << r.out;
    EXPECT_NE(r.exit_code, -1) << "crashed";
    EXPECT_EQ(test::CountLines(r.err), 1) << r.err;
    EXPECT_FALSE(fs::exists(output));
  }

  fs::path dir_;
  std::string set_;
};

TEST_F(EmCommandTest, WritesAnEmModelWhoseScoreIsTheSummary) {
  const std::string model = (dir_ / "em.h5").string();
  const auto r = RunDgmm({"em", set_, "-o", model, "--components", "2", "--seed", "3",
                          "--n-init", "4", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["samples"], 272);
  EXPECT_EQ(summary["kind"], "em");
  ASSERT_EQ(summary["commands"].size(), 1u);
  EXPECT_EQ(summary["commands"][0]["restarts"], 4);
  EXPECT_TRUE(summary["commands"][0]["converged"].get<bool>());

  const MotionModel m = ReadModel(model);
  EXPECT_EQ(m.kind, "em");
  EXPECT_EQ(m.seed, 3u);
  ASSERT_EQ(m.mixtures.size(), 1u);
  EXPECT_EQ(m.mixtures.begin()->second.size(), 2);
  EXPECT_NEAR(m.mixtures.begin()->second.total_weight(), 272.0, 1e-6);
  ASSERT_TRUE(m.metadata.count("em_options"));
  EXPECT_EQ(nlohmann::json::parse(m.metadata.at("em_options"))["n_init"], 4);

  const auto score = RunDgmm({"score", model, set_, "--json"});
  ASSERT_EQ(score.exit_code, 0) << score.err;
  const double mean = nlohmann::json::parse(score.out)["mean_log_likelihood"].get<double>();
  const double expected = summary["mean_log_likelihood"].get<double>();
  EXPECT_NEAR(mean, expected, kSameLikelihood * std::abs(expected));
}

TEST_F(EmCommandTest, SameSeedWritesTheSameSummary) {
  const std::vector<std::string> args = {"em", set_, "-o", (dir_ / "a.h5").string(),
                                         "--components", "3", "--json"};
  const auto a = RunDgmm(args), b = RunDgmm(args);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(ja["total_log_likelihood"], jb["total_log_likelihood"]);
  EXPECT_EQ(ja["commands"][0]["iterations"], jb["commands"][0]["iterations"]);
}

TEST_F(EmCommandTest, PrintsAReadableSummaryAndHelp) {
  const auto r = RunDgmm({"em", set_, "-o", (dir_ / "m.h5").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("mean log-likelihood"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("BIC"), std::string::npos) << r.out;
  const auto help = RunDgmm({"em", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--n-init"), std::string::npos);
  EXPECT_NE(help.out.find("--reg-covar"), std::string::npos);
}

TEST_F(EmCommandTest, RejectsBadInputWithOneLineAndNoOutput) {
  const std::string out = (dir_ / "bad.h5").string();
  ExpectRejected({"em", set_, "-o", out, "--components", "0"}, out);
  ExpectRejected({"em", set_, "-o", out, "--components", "273"}, out);  // 272 samples
  ExpectRejected({"em", set_, "-o", out, "--n-init", "0"}, out);
  ExpectRejected({"em", set_, "-o", out, "--reg-covar", "-1"}, out);
  ExpectRejected({"em", set_, "-o", out, "--tol", "nan"}, out);
  ExpectRejected({"em", (dir_ / "missing.h5").string(), "-o", out}, out);
  const std::string unwritable = (dir_ / "no-such-folder" / "m.h5").string();
  ExpectRejected({"em", set_, "-o", unwritable}, unwritable);
}

}  // namespace
}  // namespace dgmm
