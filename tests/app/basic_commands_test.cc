// End-to-end: import -> info -> fit -> score -> export on Old Faithful and on a small walking
// log with commands, terrain and episodes.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "io/model_io.h"
#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Runs dgmm, expects success, returns stdout parsed as JSON when `json_out`.
json Ok(const std::vector<std::string>& args, bool json_out = true) {
  RunResult r = RunDgmm(args);
  EXPECT_EQ(r.exit_code, 0) << args[0] << ": " << r.err;
  if (!json_out || r.exit_code != 0) return json();
  return json::parse(r.out, nullptr, /*allow_exceptions=*/false);
}

class OldFaithful : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = MakeTempDir("basic-old-faithful");
    Ok({"import", SourcePath("datasets/old_faithful.csv").string(), "-o", P("set.h5"),
        "--pose-cols", "eruptions,waiting"},
       false);
  }
  std::string P(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(OldFaithful, InfoDescribesTheImportedSet) {
  const json j = Ok({"info", P("set.h5"), "--json"});
  EXPECT_EQ(j["kind"], "sample_set");
  EXPECT_EQ(j["samples"], 272);
  EXPECT_EQ(j["pose_dim"], 2);
  EXPECT_EQ(j["terrain_dim"], 0);
  EXPECT_EQ(j["pose_names"], json({"eruptions", "waiting"}));
  ASSERT_EQ(j["commands"].size(), 1u);
  EXPECT_EQ(j["commands"][0]["samples"], 272);
  EXPECT_GT(j["max"][1].get<double>(), j["min"][1].get<double>());
}

TEST_F(OldFaithful, FitScoreExport) {
  const json fit = Ok({"fit", P("set.h5"), "-o", P("m.h5"), "--k", "0.7", "--seed", "1", "--json"});
  ASSERT_EQ(fit["commands"].size(), 1u);
  EXPECT_GE(fit["commands"][0]["components"].get<int>(), 1);
  EXPECT_EQ(fit["samples"], 272);

  const json info = Ok({"info", P("m.h5"), "--json"});
  EXPECT_EQ(info["kind"], "model");
  EXPECT_EQ(info["commands"][0]["components"], fit["commands"][0]["components"]);
  EXPECT_EQ(info["k"].get<double>(), 0.7);

  const json score = Ok({"score", P("m.h5"), P("set.h5"), "--json"});
  for (const char* key : {"total_log_likelihood", "mean_log_likelihood", "samples"}) {
    ASSERT_TRUE(score.contains(key)) << key;
  }
  const double total = score["total_log_likelihood"], mean = score["mean_log_likelihood"];
  EXPECT_TRUE(std::isfinite(total));
  EXPECT_TRUE(std::isfinite(mean));
  EXPECT_EQ(score["samples"], 272);
  EXPECT_NEAR(mean * 272, total, 1e-9 * std::abs(total));
  EXPECT_EQ(score["commands"][0]["samples"], 272);

  RunResult text = RunDgmm({"score", P("m.h5"), P("set.h5")});
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("272 samples"), std::string::npos) << text.out;

  Ok({"export", P("m.h5"), "-o", P("m.json")}, false);
  std::ifstream in(P("m.json"));
  const json model = json::parse(in, nullptr, false);
  ASSERT_FALSE(model.is_discarded()) << "export wrote invalid JSON";
  EXPECT_EQ(model["pose_dim"], 2);
  const json& weights = model["commands"][0]["weights"];
  EXPECT_EQ(weights.size(), fit["commands"][0]["components"].get<size_t>());
  double sum = 0;
  for (const auto& w : weights) sum += w.get<double>();
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

TEST_F(OldFaithful, SameSeedSameModelBytes) {
  Ok({"fit", P("set.h5"), "-o", P("a.h5"), "--k", "0.7", "--seed", "1"}, false);
  Ok({"fit", P("set.h5"), "-o", P("b.h5"), "--k", "0.7", "--seed", "1", "--chunk-rows", "10"},
     false);
  Ok({"fit", P("set.h5"), "-o", P("c.h5"), "--k", "0.7", "--seed", "2"}, false);
  const std::string a = Bytes(P("a.h5"));
  ASSERT_FALSE(a.empty());
  // Same seed: identical bytes, whatever the streaming chunk size.
  EXPECT_TRUE(a == Bytes(P("b.h5")));
  EXPECT_FALSE(a == Bytes(P("c.h5"))) << "a different seed should change the model";
}

TEST_F(OldFaithful, FitOptionsReachTheModel) {
  Ok({"fit", P("set.h5"), "-o", P("m.h5"), "--init-cov", "0.5,40", "--floor", "1e-5", "--variant",
      "improved", "--seed", "3"},
     false);
  const MotionModel m = ReadModel(P("m.h5"));
  EXPECT_EQ(m.dgmm_options.variant, DgmmOptions::Variant::kImproved);
  EXPECT_EQ(m.dgmm_options.covariance_floor, 1e-5);
  ASSERT_EQ(m.dgmm_options.initial_covariance_diagonal.size(), 2);
  EXPECT_EQ(m.dgmm_options.initial_covariance_diagonal[1], 40.0);
  EXPECT_EQ(m.seed, 3u);
  Ok({"fit", P("set.h5"), "-o", P("m1.h5"), "--init-cov", "2"}, false);
  EXPECT_EQ(ReadModel(P("m1.h5")).dgmm_options.initial_covariance_diagonal, Eigen::Vector2d(2, 2));
}

TEST_F(OldFaithful, FitWarnsWhenTheInitialCovarianceIsFarFromTheDataScale) {
  RunResult far = RunDgmm({"fit", P("set.h5"), "-o", P("far.h5"), "--init-cov", "1e6"});
  EXPECT_EQ(far.exit_code, 0) << far.err;
  EXPECT_NE(far.err.find("warning: "), std::string::npos) << far.err;
  EXPECT_NE(far.err.find("pooled within-command variance"), std::string::npos) << far.err;
  // The warning is one line; the rest of stderr is fit's stage line ("dgmm: fit: ... done").
  std::istringstream lines(far.err);
  int warning_lines = 0, other_lines = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("warning") != std::string::npos) {
      ++warning_lines;
    } else if (line.rfind("dgmm: fit:", 0) != 0) {
      ++other_lines;
    }
  }
  EXPECT_EQ(warning_lines, 1) << far.err;
  EXPECT_EQ(other_lines, 0) << far.err;
  RunResult data = RunDgmm({"fit", P("set.h5"), "-o", P("data.h5")});
  EXPECT_EQ(data.exit_code, 0) << data.err;
  EXPECT_EQ(data.err.find("warning"), std::string::npos) << data.err;
  const MotionModel m = ReadModel(P("data.h5"));
  EXPECT_EQ(m.dgmm_options.initial_covariance_rule, DgmmOptions::InitialCovarianceRule::kData);
  EXPECT_EQ(m.dgmm_options.covariance_rule, DgmmOptions::CovarianceRule::kPrior);
  EXPECT_EQ(m.dgmm_options.initial_covariance_diagonal.size(), 2);
  RunResult identity = RunDgmm({"fit", P("set.h5"), "-o", P("id.h5"), "--init-cov", "identity",
                                "--covariance", "literal"});
  EXPECT_EQ(identity.exit_code, 0) << identity.err;
  const MotionModel id = ReadModel(P("id.h5"));
  EXPECT_EQ(id.dgmm_options.initial_covariance_diagonal, Eigen::Vector2d(1, 1));
  EXPECT_EQ(id.dgmm_options.covariance_rule, DgmmOptions::CovarianceRule::kLiteral);
}

TEST(BasicCommands, HelpOnEverySubcommand) {
  for (const char* command : {"import", "info", "fit", "score", "export"}) {
    RunResult r = RunDgmm({command, "--help"});
    EXPECT_EQ(r.exit_code, 0) << command;
    EXPECT_NE(r.out.find(command), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--"), std::string::npos) << r.out;
  }
}

// Commands, terrain, episodes and standardisation on a small walking log.
TEST(BasicCommands, CommandsTerrainEpisodesAndStandardisation) {
  const fs::path dir = MakeTempDir("basic-walk");
  auto p = [&](const std::string& n) { return (dir / n).string(); };
  {
    std::ofstream csv(p("walk.csv"));
    csv << "speed,turn,dx,dyaw,pitch,run\n";
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int i = 0; i < 600; ++i) {
      const int c = i % 3;
      const double pitch = 0.1 * normal(rng);
      csv << 0.5 * (c > 0) << "," << (c == 2) << "," << 0.3 * c + 2 * pitch + 0.05 * normal(rng)
          << "," << 10.0 * (c == 2) + normal(rng) << "," << pitch << "," << i / 100 << "\n";
    }
  }
  const std::vector<std::string> cols = {"--command-cols", "speed,turn", "--pose-cols",   "dx,dyaw",
                                         "--terrain-cols", "pitch",      "--episode-col", "run",
                                         "--source",       "real"};
  auto import = [&](const std::string& out, bool standardize) {
    std::vector<std::string> args = {"import", p("walk.csv"), "-o", p(out)};
    args.insert(args.end(), cols.begin(), cols.end());
    if (standardize) args.push_back("--standardize");
    Ok(args, false);
  };
  import("raw.h5", false);
  import("std.h5", true);
  const json info = Ok({"info", p("raw.h5"), "--json"});
  EXPECT_EQ(info["terrain_dim"], 1);
  EXPECT_EQ(info["source"], "real");
  EXPECT_EQ(info["episodes"], 6);
  ASSERT_EQ(info["commands"].size(), 3u);
  EXPECT_EQ(info["commands"][0]["label"], "0,0");
  EXPECT_EQ(info["commands"][2]["label"], "0.5,1");
  for (const auto& c : info["commands"]) EXPECT_EQ(c["samples"], 200);
  EXPECT_EQ(Ok({"info", p("std.h5"), "--json"})["standardized"], true);

  // A model fitted on standardised data scores raw and standardised sets alike, in raw units.
  Ok({"fit", p("std.h5"), "-o", p("m.h5"), "--seed", "1"}, false);
  const json on_std = Ok({"score", p("m.h5"), p("std.h5"), "--json"});
  const json on_raw = Ok({"score", p("m.h5"), p("raw.h5"), "--json"});
  const double a = on_std["total_log_likelihood"], b = on_raw["total_log_likelihood"];
  EXPECT_NEAR(a, b, 1e-6 * std::abs(a));
  EXPECT_EQ(on_raw["commands"].size(), 3u);

  Ok({"fit", p("raw.h5"), "-o", p("nz.h5"), "--without-terrain"}, false);
  EXPECT_EQ(Ok({"info", p("nz.h5"), "--json"})["terrain_dim"], 0);
  Ok({"export", p("m.h5"), "-o", p("m.json")}, false);
  std::ifstream in(p("m.json"));
  const json exported = json::parse(in, nullptr, false);
  ASSERT_FALSE(exported.is_discarded());
  EXPECT_TRUE(exported["commands"][0].contains("raw_units"));
  EXPECT_EQ(exported["transform"]["offset"].size(), 3u);
}

}  // namespace
}  // namespace dgmm::test
