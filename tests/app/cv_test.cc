// End-to-end tests of `dgmm cv` and `dgmm tune-k` on small synthetic sets written to HDF5.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/sample_set_io.h"
#include "tests/app/run_dgmm.h"
#include "tests/tune/synthetic.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;

// A 3-command set whose pose change depends on the terrain, written once per test.
std::string WriteTerrainSet(const fs::path& dir) {
  const std::string path = (dir / "terrain.h5").string();
  WriteSampleSet(MakeTerrainSet(3, 20, 1.0, 4), path);
  return path;
}

TEST(CvCommand, JsonTableWithTerrainHelping) {
  const fs::path dir = MakeTempDir("cv_json");
  const std::string set = WriteTerrainSet(dir);
  const RunResult r =
      RunDgmm({"cv", set, "--k", "0.5", "--folds", "4", "--repeats", "2", "--json", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["samples"], 60);
  EXPECT_EQ(j["folds"], 4);
  for (const char* row : {"dgmm_without_terrain", "dgmm_with_terrain", "em_bic_without_terrain",
                          "em_bic_with_terrain"}) {
    ASSERT_TRUE(j["rows"].contains(row)) << row;
    EXPECT_EQ(j["rows"][row]["per_repeat"].size(), 2u);
  }
  EXPECT_GT(j["rows"]["dgmm_with_terrain"]["mean"].get<double>(),
            j["rows"]["dgmm_without_terrain"]["mean"].get<double>());
  EXPECT_GT(j["rows"]["em_bic_with_terrain"]["mean"].get<double>(),
            j["rows"]["em_bic_without_terrain"]["mean"].get<double>());
  // The paired terrain change is the difference of the rows.
  for (const std::string family : {"dgmm", "em_bic"}) {
    const double with = j["rows"][family + "_with_terrain"]["mean"], without = j["rows"][family + "_without_terrain"]["mean"];
    EXPECT_NEAR(j["terrain_change"][family]["mean"].get<double>(), with - without, 1e-6 * std::abs(without)) << family;
    EXPECT_GT(j["terrain_change"][family]["paired_standard_error"].get<double>(), 0) << family;
  }
  EXPECT_TRUE(r.err.empty()) << "--quiet silences progress: " << r.err;
  // Without --quiet and without a terminal: one line for the stage, no carriage returns.
  const RunResult loud = RunDgmm({"cv", set, "--k", "0.5", "--folds", "4", "--repeats", "2", "--json"});
  ASSERT_EQ(loud.exit_code, 0) << loud.err;
  EXPECT_EQ(CountLines(loud.err), 1) << loud.err;
  EXPECT_NE(loud.err.find("cv folds: 8/8 done in"), std::string::npos) << loud.err;
  EXPECT_EQ(loud.err.find('\r'), std::string::npos);
}

TEST(CvCommand, TextTableAndThreadIndependence) {
  const fs::path dir = MakeTempDir("cv_text");
  const std::string set = WriteTerrainSet(dir);
  const RunResult text = RunDgmm({"cv", set, "--folds", "3", "--repeats", "2", "--no-em"});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("DGMM without terrain"), std::string::npos);
  EXPECT_NE(text.out.find("DGMM with terrain"), std::string::npos);
  EXPECT_EQ(text.out.find("EM-BIC"), std::string::npos);
  EXPECT_NE(text.out.find("conditioning on terrain changes DGMM by +"), std::string::npos) << text.out;
  std::vector<std::string> args = {"cv", set, "--folds", "3", "--repeats", "2", "--json"};
  args.insert(args.end(), {"--threads", "1"});
  const auto one = nlohmann::json::parse(RunDgmm(args).out);
  args.back() = "2";
  const auto two = nlohmann::json::parse(RunDgmm(args).out);
  EXPECT_EQ(one["rows"], two["rows"]);
}

TEST(CvCommand, BadInputIsOneLineAndNonZero) {
  const fs::path dir = MakeTempDir("cv_bad");
  const std::string set = WriteTerrainSet(dir);
  for (const std::vector<std::string>& args : {std::vector<std::string>{"cv", set, "--k", "0"},
                                               {"cv", set, "--k", "-1"},
                                               {"cv", set, "--k", "nan"},
                                               {"cv", set, "--folds", "1"},
                                               {"cv", set, "--repeats", "0"},
                                               {"cv", (dir / "missing.h5").string()},
                                               {"tune-k", set, "--folds", "1"},
                                               {"tune-k", set, "--k-min", "0"},
                                               {"tune-k", (dir / "missing.h5").string()}}) {
    const RunResult r = RunDgmm(args);
    EXPECT_NE(r.exit_code, 0) << args[1] << " " << (args.size() > 2 ? args[2] : "");
    EXPECT_NE(r.exit_code, -1) << "crashed";
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
  }
}

TEST(TuneKCommand, ChoosesKInsideTheBracketAndWritesTheCurve) {
  const fs::path dir = MakeTempDir("tune_k");
  const std::string set = WriteTerrainSet(dir);
  const std::string csv = (dir / "curve.csv").string();
  const RunResult r = RunDgmm({"tune-k", set, "--folds", "3", "--repeats", "2", "--grid-points",
                               "4", "--refine-points", "1", "--curve-csv", csv, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& rec = j["recommended"];
  const auto& search = j["k_search"];
  const double k = rec["k"];
  const bool plateau = search["plateau"]["flat"];
  // The joint step's record; when it moved the choice, k is a member of its plateau.
  const auto& joint = j["joint"];
  ASSERT_TRUE(joint.is_object()) << r.out;
  for (const char* field : {"surrogate", "accepted", "evaluations", "fit_report", "plateau"}) {
    EXPECT_TRUE(joint.contains(field)) << field;
  }
  EXPECT_LE(joint["start"]["log_likelihood"].get<double>(),
            rec["log_likelihood"].get<double>() + joint["tolerance"].get<double>());
  if (joint["start"]["k"].get<double>() != k) {
    EXPECT_GE(k, joint["plateau"]["k_range"][0].get<double>());
    EXPECT_LE(k, joint["plateau"]["k_range"][1].get<double>());
  } else if (plateau) {  // k is the simplest member of the plateau, which is stated with its range
    EXPECT_GE(k, search["plateau"]["k_range"][0].get<double>());
    EXPECT_LE(k, search["plateau"]["k_range"][1].get<double>());
    EXPECT_NE(search["rule"].get<std::string>().find("plateau"), std::string::npos);
    EXPECT_FALSE(search["plateau"]["meaning"].get<std::string>().empty());
  } else {
    EXPECT_GE(k, search["bracket"][0].get<double>() * (1 - 1e-9));
    EXPECT_LE(k, search["bracket"][1].get<double>() * (1 + 1e-9));
    EXPECT_DOUBLE_EQ(k, search["quadratic_refinement"]["k_at_maximum"].get<double>());
  }
  // Grid and refinement, plus the chosen k's own evaluation unless it came from the plateau.
  EXPECT_EQ(search["curve"].size(), 4u + 1u + (plateau ? 0u : 1u));
  EXPECT_FALSE(j["folds_by"].get<std::string>().empty());
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "k,log_likelihood,sd,standard_error,smoothed,role");
  // An unwritable output fails before the run and leaves nothing behind.
  const std::string bad = (dir / "no_such_dir" / "curve.csv").string();
  const RunResult fail = RunDgmm({"tune-k", set, "--curve-csv", bad});
  EXPECT_NE(fail.exit_code, 0);
  EXPECT_FALSE(fs::exists(bad));
}

}  // namespace
}  // namespace dgmm::test
