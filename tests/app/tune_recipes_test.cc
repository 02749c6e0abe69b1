// End-to-end tests of what `dgmm tune` and `dgmm cv` print for a user to act on (issue #24):
// recipes that run, folds the data supports, JSON keys that say what they are, elapsed times,
// plurals and misspelt commands.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io/sample_set_io.h"
#include "tests/app/run_dgmm.h"
#include "tests/tune/synthetic.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The text after "<prefix>" on the line of `text` that starts with it ("" when none).
std::string LineAfter(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) == 0) return line.substr(prefix.size());
  }
  return "";
}

// The words of a printed command line, without the leading "dgmm" (paths have no spaces here).
std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  if (!words.empty() && words[0] == "dgmm") words.erase(words.begin());
  return words;
}

// `episodes` trials in recording order over the set (one episode per trial).
SampleSet WithEpisodes(SampleSet set, int episodes) {
  set.episode.resize(set.size());
  set.step.resize(set.size());
  for (int i = 0; i < set.size(); ++i) set.episode(i) = i * episodes / set.size(), set.step(i) = i;
  return set;
}

SampleSet WithoutTerrain(SampleSet set) {
  set.z.resize(set.size(), 0);
  set.z_names.clear();
  set.z_units.clear();
  return set;
}

// Runs tune (text), then every command line it printed; cv's DGMM row reproduces tune's value.
void RunPrintedRecipes(const std::string& set, const fs::path& dir, bool terrain) {
  std::vector<std::string> args = {"tune",          set,      "--repeats",       "2",
                                   "--grid-points", "4",      "--refine-points", "1",
                                   "--no-joint",    "--quiet"};
  const RunResult tune = RunDgmm(args);
  ASSERT_EQ(tune.exit_code, 0) << tune.err;
  args.push_back("--json");
  const json j = json::parse(RunDgmm(args).out);
  const std::string fit = LineAfter(tune.out, "fit with: ");
  const std::string cv = LineAfter(tune.out, "cross-validate with: ");
  ASSERT_FALSE(fit.empty()) << tune.out;
  ASSERT_FALSE(cv.empty()) << tune.out;
  EXPECT_EQ(fit, j["recommended"]["fit_command"]);
  EXPECT_EQ(cv, j["recommended"]["cv_command"]);
  EXPECT_EQ(fit.find("--without-terrain") != std::string::npos, !terrain) << fit;
  std::vector<std::string> fit_words = Words(fit);
  for (auto& w : fit_words) {
    if (w == "model.h5") w = (dir / "model.h5").string();
  }
  const RunResult fitted = RunDgmm(fit_words);
  EXPECT_EQ(fitted.exit_code, 0) << fit << "\n" << fitted.err;
  EXPECT_TRUE(fs::exists(dir / "model.h5"));
  std::vector<std::string> cv_words = Words(cv);
  cv_words.insert(cv_words.end(), {"--no-em", "--json", "--quiet"});
  const RunResult crossed = RunDgmm(cv_words);
  ASSERT_EQ(crossed.exit_code, 0) << cv << "\n" << crossed.err;
  const json c = json::parse(crossed.out);
  const char* row = terrain ? "dgmm_with_terrain" : "dgmm_without_terrain";
  ASSERT_TRUE(c["rows"].contains(row)) << crossed.out;
  EXPECT_NEAR(c["rows"][row]["mean"].get<double>(),
              j["recommended"]["log_likelihood"].get<double>(),
              1e-6 * std::abs(j["recommended"]["log_likelihood"].get<double>()) + 1e-9);
  EXPECT_EQ(c["folds_by"], j["folds_by"]);
}

TEST(TuneRecipes, EveryPrintedLineRunsWithAndWithoutTerrain) {
  const fs::path dir = MakeTempDir("tune_recipes");
  const std::string with = (dir / "with.h5").string(), without = (dir / "without.h5").string();
  WriteSampleSet(WithEpisodes(MakeTerrainSet(3, 16, 1.0, 4), 8), with);
  WriteSampleSet(WithEpisodes(WithoutTerrain(MakeTerrainSet(3, 16, 1.0, 4)), 8), without);
  RunPrintedRecipes(with, dir, true);
  RunPrintedRecipes(without, dir, false);
  // tune --without-terrain on a set with terrain: the recipe says --without-terrain, and cv runs
  // it.
  const RunResult r = RunDgmm({"tune", with, "--without-terrain", "--repeats", "1", "--grid-points",
                               "3", "--refine-points", "0", "--no-joint", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> cv = Words(LineAfter(r.out, "cross-validate with: "));
  ASSERT_NE(std::find(cv.begin(), cv.end(), "--without-terrain"), cv.end());
  const RunResult c = RunDgmm(cv);
  EXPECT_EQ(c.exit_code, 0) << c.err;
  EXPECT_EQ(c.out.find("DGMM with terrain"), std::string::npos) << c.out;
}

TEST(TuneRecipes, UserDgmmFlagsAreCarriedIntoTheRecipes) {
  const fs::path dir = MakeTempDir("tune_recipes_flags");
  const std::string set = (dir / "set.h5").string();
  WriteSampleSet(MakeTerrainSet(2, 20, 1.0, 5), set);
  const RunResult r =
      RunDgmm({"tune", set, "--covariance", "blend", "--variant", "improved", "--repeats", "1",
               "--grid-points", "3", "--refine-points", "0", "--no-joint", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* prefix : {"fit with: ", "cross-validate with: "}) {
    const std::string line = LineAfter(r.out, prefix);
    EXPECT_NE(line.find("--covariance blend"), std::string::npos) << line;
    EXPECT_NE(line.find("--variant improved"), std::string::npos) << line;
    // The blend rule has no nu0: no --prior-count was tuned, none is printed.
    EXPECT_EQ(line.find("--prior-count"), std::string::npos) << line;
  }
}

TEST(TuneRecipes, WarningsSuggestOnlyFlagsTheCommandAccepts) {
  const fs::path dir = MakeTempDir("tune_recipes_warn");
  const std::string set = (dir / "set.h5").string();
  WriteSampleSet(MakeTerrainSet(2, 8, 1.0, 6), set);  // 8 samples, 14 parameters in d = 4
  for (const std::string command : {"em", "cv", "tune"}) {
    std::vector<std::string> args = {command, set};
    if (command == "em")
      args.insert(args.end(), {"-o", (dir / "em.h5").string(), "--components", "1"});
    if (command == "tune")
      args.insert(args.end(), {"--grid-points", "3", "--refine-points", "0", "--no-joint"});
    if (command != "em") args.insert(args.end(), {"--repeats", "1"});
    const RunResult r = RunDgmm(args);
    ASSERT_EQ(r.exit_code, 0) << command << ": " << r.err;
    const std::string warning = LineAfter(r.err, "dgmm: warning: " + command + ": fewer samples");
    ASSERT_FALSE(warning.empty()) << command << ": " << r.err;
    EXPECT_EQ(warning.find("--pose-dims") != std::string::npos, command != "em") << warning;
    // The suggested flag is accepted by the command the warning names.
    args.push_back("--without-terrain");
    EXPECT_NE(warning.find("dgmm " + command + " --without-terrain"), std::string::npos) << warning;
    EXPECT_EQ(RunDgmm(args).exit_code, 0) << command << " --without-terrain";
  }
}

TEST(SmallData, DefaultFoldsWorkOnFortyOneShortTrials) {
  // 41 trials of 15 commands, one sample per trial: some command has two or three samples, so
  // 10 folds stratified by command would be refused; 10 folds of whole trials are fine.
  SampleSet set = WithoutTerrain(MakeTerrainSet(15, 3, 1.0, 7));
  std::vector<int> rows;
  for (int i = 0; i < 41; ++i) rows.push_back(i);
  set = WithEpisodes(set.Subset(rows), 41);
  const fs::path dir = MakeTempDir("small_data");
  const std::string path = (dir / "trials.h5").string();
  WriteSampleSet(set, path);
  const RunResult cv = RunDgmm({"cv", path, "--repeats", "1", "--quiet"});
  ASSERT_EQ(cv.exit_code, 0) << cv.err;
  EXPECT_EQ(LineAfter(cv.out, "folds: ")
                .rfind("automatic: 10 folds of whole episodes (41 episodes, at most 10 folds)", 0),
            0u)
      << cv.out;
  // The EM reference is omitted with the reason, not printed as a result.
  EXPECT_NE(cv.out.find("EM-BIC without terrain: omitted, command"), std::string::npos) << cv.out;
  const RunResult tune = RunDgmm({"tune", path, "--repeats", "1", "--grid-points", "3",
                                  "--refine-points", "0", "--no-joint", "--quiet"});
  ASSERT_EQ(tune.exit_code, 0) << tune.err;
  EXPECT_FALSE(LineAfter(tune.out, "folds: ").empty()) << tune.out;
  // Six trials: leave-one-trial-out.
  const std::string six = (dir / "six.h5").string();
  WriteSampleSet(WithEpisodes(WithoutTerrain(MakeTerrainSet(2, 6, 1.0, 8)), 6), six);
  const RunResult loo = RunDgmm({"cv", six, "--repeats", "1", "--no-em", "--quiet"});
  ASSERT_EQ(loo.exit_code, 0) << loo.err;
  EXPECT_NE(LineAfter(loo.out, "folds: ").find("leave-one-episode-out (6 episodes"),
            std::string::npos)
      << loo.out;
  // No valid split: one sample per command and no episodes -> one line naming --folds and the fix.
  const std::string tiny = (dir / "tiny.h5").string();
  WriteSampleSet(WithoutTerrain(MakeTerrainSet(3, 1, 1.0, 9)), tiny);
  for (const char* command : {"cv", "tune"}) {
    const RunResult bad = RunDgmm({command, tiny, "--repeats", "1"});
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
    EXPECT_EQ(CountLines(bad.err), 1) << bad.err;
    EXPECT_NE(bad.err.find("--folds"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("record more samples"), std::string::npos) << bad.err;
  }
  // An explicit --folds the data cannot support names the fix.
  const RunResult too_many = RunDgmm({"cv", six, "--folds", "7", "--stratified", "--repeats", "1"});
  EXPECT_EQ(too_many.exit_code, 2);
  EXPECT_NE(too_many.err.find("omit --folds"), std::string::npos) << too_many.err;
  // The suggested --folds works.
  const size_t use = too_many.err.find("use --folds ");
  ASSERT_NE(use, std::string::npos) << too_many.err;
  const std::string suggested =
      too_many.err.substr(use + 12, too_many.err.find(' ', use + 12) - use - 12);
  const RunResult fixed =
      RunDgmm({"cv", six, "--folds", suggested, "--stratified", "--repeats", "1", "--quiet"});
  EXPECT_EQ(fixed.exit_code, 0) << suggested << ": " << fixed.err;
}

TEST(TuneJson, KeysSayWhatTheyAre) {
  const fs::path dir = MakeTempDir("tune_json");
  const std::string path = (dir / "set.h5").string();
  WriteSampleSet(MakeTerrainSet(3, 12, 1.0, 10), path);
  // Every evaluation equivalent (a huge tolerance): a plateau over the whole grid, k chosen at the
  // simplest end, which is an edge of the grid.
  const RunResult r =
      RunDgmm({"tune", path, "--repeats", "1", "--grid-points", "4", "--refine-points", "1",
               "--no-joint", "--plateau-tolerance", "1e9", "--json", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* key : {"k", "init_scale", "prior_count", "log_likelihood", "standard_error",
                          "components_per_command", "flags", "fit_command", "cv_command"}) {
    EXPECT_TRUE(j["recommended"].contains(key)) << key;
  }
  EXPECT_FALSE(j.contains("fit")) << "the quadratic is under k_search.quadratic_refinement";
  const json& k = j["k_search"];
  EXPECT_TRUE(k["quadratic_refinement"].contains("k_at_maximum"));
  EXPECT_TRUE(k["plateau"]["spans_whole_grid"].get<bool>()) << k["plateau"];
  EXPECT_NE(k["plateau"]["meaning"].get<std::string>().find("k not identifiable from this data"),
            std::string::npos);
  const double chosen = j["recommended"]["k"];
  const bool at_end = chosen <= k["grid"]["k_min"].get<double>() * (1 + 1e-9) ||
                      chosen >= k["grid"]["k_max"].get<double>() * (1 - 1e-9);
  EXPECT_TRUE(at_end) << chosen;
  EXPECT_TRUE(k["optimum_at_grid_edge"].get<bool>());
  EXPECT_EQ(k["grid_edge"],
            chosen >= k["grid"]["k_max"].get<double>() * (1 - 1e-9) ? "high" : "low");
  // The text says the same in words.
  const RunResult text =
      RunDgmm({"tune", path, "--repeats", "1", "--grid-points", "4", "--refine-points", "1",
               "--no-joint", "--plateau-tolerance", "1e9", "--quiet"});
  EXPECT_NE(text.out.find("k not identifiable from this data"), std::string::npos) << text.out;
}

TEST(Output, ElapsedTimesPluralsAndMisspeltCommands) {
  const fs::path dir = MakeTempDir("output_reads_right");
  const std::string path = (dir / "set.h5").string();
  WriteSampleSet(MakeTerrainSet(2, 30, 1.0, 11), path);
  // The stage line's time is the stage's, not the time since its last call.
  const RunResult r = RunDgmm({"tune", path, "--repeats", "3", "--grid-points", "5", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double seconds = json::parse(r.out)["seconds"];
  const std::string stage = LineAfter(r.err, "dgmm: tune cross-validations: ");
  const size_t in = stage.find("done in ");
  ASSERT_NE(in, std::string::npos) << r.err;
  const std::string shown = stage.substr(in + 8);
  if (shown != "under 1 ms")
    EXPECT_GE(std::stod(shown), 0.5 * seconds) << stage << " vs " << seconds;
  EXPECT_EQ(r.err.find("done in 0.0 s"), std::string::npos) << r.err;
  // "1 component", never "1 components".
  const RunResult em = RunDgmm({"em", path, "-o", (dir / "em.h5").string(), "--components", "1"});
  ASSERT_EQ(em.exit_code, 0) << em.err;
  EXPECT_NE(em.out.find("1 component,"), std::string::npos) << em.out;
  EXPECT_EQ(em.out.find("1 components"), std::string::npos) << em.out;
  const RunResult info = RunDgmm({"info", (dir / "em.h5").string()});
  EXPECT_EQ(info.out.find("1 components"), std::string::npos) << info.out;
  // A misspelt subcommand with --help is an error naming it, not the main help with exit 0.
  const RunResult typo = RunDgmm({"tnue", "--help"});
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_EQ(CountLines(typo.err), 1) << typo.err;
  EXPECT_NE(typo.err.find("unknown command 'tnue' (did you mean 'tune'?)"), std::string::npos)
      << typo.err;
  EXPECT_TRUE(typo.out.empty()) << typo.out;
  EXPECT_EQ(RunDgmm({"tune", "--help"}).exit_code, 0);
}

}  // namespace
}  // namespace dgmm::test
