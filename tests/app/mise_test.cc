// End-to-end: `dgmm mise` agrees with the library's closed form, is symmetric and zero for a
// model against itself, and rejects mismatched models.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/mise.h"
#include "io/model_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

class MiseCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(MakeTempDir("mise-command"));
    const std::string csv = SourcePath("datasets/old_faithful.csv").string();
    ASSERT_EQ(RunDgmm({"import", csv, "-o", P("of.h5"), "--pose-cols", "eruptions,waiting",
                       "--standardize"}).exit_code, 0);
    ASSERT_EQ(RunDgmm({"import", csv, "-o", P("of1.h5"), "--pose-cols", "waiting"}).exit_code, 0);
    ASSERT_EQ(RunDgmm({"fit", P("of.h5"), "-o", P("a.h5"), "--seed", "1"}).exit_code, 0);
    ASSERT_EQ(RunDgmm({"fit", P("of.h5"), "-o", P("b.h5"), "--seed", "7", "--k", "0.1"}).exit_code,
              0);
    ASSERT_EQ(RunDgmm({"fit", P("of1.h5"), "-o", P("c.h5")}).exit_code, 0);
  }
  static std::string P(const std::string& name) { return (*dir_ / name).string(); }
  static double Mise(const std::string& a, const std::string& b) {
    RunResult r = RunDgmm({"mise", P(a), P(b), "--json"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return nlohmann::json::parse(r.out)["mise"].get<double>();
  }
  static inline fs::path* dir_ = nullptr;
};

TEST_F(MiseCommandTest, AgreesWithClosedFormInTheFittedSpace) {
  const MotionModel a = ReadModel(P("a.h5")), b = ReadModel(P("b.h5"));
  const double expected = IntegratedSquaredError(a.mixtures.begin()->second,
                                                 b.mixtures.begin()->second);
  EXPECT_NEAR(Mise("a.h5", "b.h5"), expected, 1e-12 + 1e-9 * expected);
  RunResult r = RunDgmm({"mise", P("a.h5"), P("b.h5"), "--json"});
  EXPECT_EQ(nlohmann::json::parse(r.out)["space"], "standardised");
}

TEST_F(MiseCommandTest, SymmetricAndZeroForItself) {
  EXPECT_NEAR(Mise("a.h5", "b.h5"), Mise("b.h5", "a.h5"), 1e-12);
  EXPECT_NEAR(Mise("a.h5", "a.h5"), 0.0, 1e-12);
}

// Raw units stretch eruptions by ~1.1 and waiting by ~13.6: the ISE shrinks by their product.
TEST_F(MiseCommandTest, RawUnitsScaleByTheJacobian) {
  RunResult r = RunDgmm({"mise", P("a.h5"), P("b.h5"), "--raw", "--json"});
  ASSERT_EQ(r.exit_code, 0);
  const MotionModel a = ReadModel(P("a.h5"));
  const double jacobian = a.transform.scale.prod();
  EXPECT_NEAR(nlohmann::json::parse(r.out)["mise"].get<double>() * jacobian,
              Mise("a.h5", "b.h5"), 1e-9);
}

TEST_F(MiseCommandTest, MismatchedOrMissingModelsAreErrors) {
  RunResult r = RunDgmm({"mise", P("a.h5"), P("c.h5")});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("dimensions"), std::string::npos);
  r = RunDgmm({"mise", P("a.h5"), P("of.h5")});  // a sample set, not a model
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  r = RunDgmm({"mise", P("a.h5"), P("a.h5"), "--command", "9"});
  EXPECT_NE(r.exit_code, 0);
}

// The hidden `experiment old-faithful` reports how all fits at k ended: with --runs above
// --max-attempts exactly --max-attempts shuffles, each counted once under its number of Gaussians,
// and the 2-Gaussian count equals the MISE runs.
TEST_F(MiseCommandTest, ExperimentCountsHowEveryFitEnded) {
  const fs::path out = *dir_ / "experiment";
  fs::create_directories(out);
  ASSERT_EQ(RunDgmm({"em", P("of.h5"), "-o", P("em.h5"), "--components", "2", "--seed", "1"})
                .exit_code, 0);
  RunResult r = RunDgmm({"--quiet", "experiment", "old-faithful", P("of.h5"), "--em", P("em.h5"),
                         "--out-dir", out.string(), "--variants", "faithful-literal", "--k", "0.7",
                         "--grid-points", "2", "--seeds-per-k", "1", "--runs", "1000",
                         "--max-attempts", "60", "--folds", "2", "--cv-seeds", "1", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json mise = nlohmann::json::parse(r.out)["faithful-literal"]["mise"];
  int total = 0, twos = 0, previous = 0;
  for (const auto& entry : mise["components_histogram"]) {
    const int components = entry[0].get<int>(), fits = entry[1].get<int>();
    EXPECT_GT(components, previous);  // ascending, each number once
    EXPECT_GT(fits, 0);
    previous = components;
    total += fits;
    if (components == 2) twos = fits;
  }
  EXPECT_EQ(total, 60);
  EXPECT_EQ(mise["attempts"].get<int>(), 60);
  EXPECT_EQ(twos, mise["runs"].get<int>());
}

}  // namespace
}  // namespace dgmm::test
