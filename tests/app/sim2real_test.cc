// End-to-end `dgmm sim2real` on the shipped MuJoCo pairs (datasets/sim2real, made by
// scripts/make_sim2real_pairs.sh). The planted value of an effect, in the effect's units, is what
// the same analysis fits on an independent recording of the same physics (<pair>/oracle.h5); see
// docs/sim2real.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/app/run_dgmm.h"

namespace dgmm::test {
namespace {

using nlohmann::json;

json RunSim2Real(const std::string& real, const std::string& name) {
  auto dir = MakeTempDir("sim2real-" + name);
  RunResult r = RunDgmm({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(),
                         "--real", SourcePath(real).string(), "-o", dir.string(), "--no-figures",
                         "--bootstrap", "10", "--permutations", "500"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "report.json");
  json j = json::parse(in, nullptr, /*allow_exceptions=*/false);
  EXPECT_FALSE(j.is_discarded());
  EXPECT_TRUE(std::filesystem::exists(dir / "report.html"));
  EXPECT_TRUE(std::filesystem::exists(dir / "corrected_model.h5"));
  return j;
}

double Parameter(const json& effect, const std::string& name) {
  for (const auto& p : effect["parameters"])
    if (p["name"] == name) return p["value"].get<double>();
  ADD_FAILURE() << "no parameter " << name;
  return NAN;
}

// The recovered parameter may differ from the planted one by this share (the bound).
constexpr double kParameterTolerance = 0.3;

// The parameter of an effect that the oracle analysis determines best: the largest
// |value| / half-width of its 95% bootstrap interval (for a one-parameter effect, that one).
std::string BestDeterminedParameter(const json& effect) {
  std::string best;
  double best_t = -1;
  for (const auto& p : effect["parameters"]) {
    const double v = p["value"].get<double>();
    const double half = 0.5 * (p["ci95"][1].get<double>() - p["ci95"][0].get<double>());
    const double t = std::abs(v) / std::max(half, 1e-12);
    if (t > best_t) {
      best_t = t;
      best = p["name"].get<std::string>();
    }
  }
  return best;
}

// The proof on a concealed effect: the planted effect is ranked first, its parameter is
// within 30% of the planted value, the corrected model closes >= 70% of the gap, the pooled
// per-command test of x flags nothing while the terrain/sequence-aware tests flag regions.
void ExpectPlantedEffectRecovered(const std::string& pair, const std::string& planted_effect) {
  json j = RunSim2Real("datasets/sim2real/" + pair + "/real.h5", pair);
  json oracle = RunSim2Real("datasets/sim2real/" + pair + "/oracle.h5", pair + "-oracle");
  ASSERT_FALSE(oracle["effects"].empty());
  ASSERT_EQ(oracle["effects"][0]["effect"], planted_effect) << "the oracle defines the planted value";
  ASSERT_FALSE(j["effects"].empty()) << j["conclusion"];
  EXPECT_EQ(j["effects"][0]["effect"], planted_effect) << j["conclusion"];
  const std::string name = BestDeterminedParameter(oracle["effects"][0]);
  const double planted = Parameter(oracle["effects"][0], name);
  EXPECT_NEAR(Parameter(j["effects"][0], name), planted, kParameterTolerance * std::abs(planted))
      << pair << ": parameter " << name;
  EXPECT_GE(j["gap_closed"].get<double>(), 0.7) << j["conclusion"];
  EXPECT_TRUE(j["significant_mismatch"].get<bool>());
  EXPECT_EQ(j["pooled_x_flagged_commands"].get<int>(), 0) << "the pooled test must not reveal it";
  EXPECT_GE(j["conditional_flagged_regions"].get<int>(), 3);
}

TEST(Sim2RealApp, SlipPairRanksSlipFirstWithPlantedCreepAndClosesTheGap) {
  ExpectPlantedEffectRecovered("slip", "slope_slip");
}

TEST(Sim2RealApp, PayloadPairRanksPayloadFirstWithPlantedDriftAndClosesTheGap) {
  ExpectPlantedEffectRecovered("payload", "payload_offset");
}

TEST(Sim2RealApp, WeakLegPairRanksAsymmetryFirstWithPlantedDriftAndClosesTheGap) {
  ExpectPlantedEffectRecovered("weak_leg", "actuator_asymmetry");
}

TEST(Sim2RealApp, NullPairStaysClean) {
  json j = RunSim2Real("datasets/sim2real/null/real.h5", "null");
  EXPECT_FALSE(j["significant_mismatch"].get<bool>());
  EXPECT_EQ(j["pooled_x_flagged_commands"].get<int>(), 0);
  EXPECT_EQ(j["conditional_flagged_regions"].get<int>(), 0);
  EXPECT_TRUE(j["effects"].empty());
  EXPECT_TRUE(j["unexplained"].empty());
}

// --sim-config: the re-simulated friction that best explains the real set is the planted one
// (0.7, in the simulator's own units) within 30%, and fits better than the nominal friction.
TEST(Sim2RealApp, SlipPairRecalibratesFriction) {
  auto dir = MakeTempDir("sim2real-recal");
  RunResult r = RunDgmm({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(),
                         "--real", SourcePath("datasets/sim2real/slip/real.h5").string(), "-o",
                         dir.string(), "--no-figures", "--bootstrap", "0", "--sim-config",
                         SourcePath("datasets/sim2real/configs/nominal.json").string(), "--json",
                         "--no-knobs", "--legacy-resim"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json j = json::parse(r.out);
  ASSERT_TRUE(j.contains("recalibration"));
  const json& recal = j["recalibration"];
  ASSERT_TRUE(recal.contains("best")) << recal.dump();
  const double planted_friction = 0.7;  // datasets/sim2real/configs/slip.json
  EXPECT_NEAR(recal["best"].get<double>(), planted_friction, kParameterTolerance * planted_friction);
  EXPECT_GT(recal["improvement_nats_per_sample"].get<double>(), 0.0);
}

// The "recalibration" object of `sim2real --sim-config nominal.json` on a shipped pair.
json RunRecalibration(const std::string& real, const std::string& name) {
  auto dir = MakeTempDir("sim2real-recal-" + name);
  RunResult r = RunDgmm({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(),
                         "--real", SourcePath(real).string(), "-o", dir.string(), "--no-figures",
                         "--bootstrap", "0", "--sim-config",
                         SourcePath("datasets/sim2real/configs/nominal.json").string(), "--json",
                         "--no-knobs", "--legacy-resim"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  json j = json::parse(r.out, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.contains("recalibration")) return json::object();
  // The recalibrated config is also written on its own, and the simulator accepts it.
  if (j["recalibration"].contains("recalibrated_config")) {
    const auto config = dir / "recalibrated_config.json";
    EXPECT_TRUE(std::filesystem::exists(config));
    EXPECT_EQ(RunDgmm({"simulate", "--config", config.string(), "--print-config"}).exit_code, 0);
    // The report summarises the scans in a table, with the check.
    std::ifstream html(dir / "report.html");
    const std::string text((std::istreambuf_iterator<char>(html)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("Re-simulation with the fitted physical parameters</h3><table>"), std::string::npos);
    EXPECT_NE(text.find("recalibrated config"), std::string::npos);
  }
  return j["recalibration"];
}

const json* FindScan(const json& recal, const std::string& effect) {
  if (!recal.contains("scans")) return nullptr;
  for (const auto& s : recal["scans"])
    if (s["effect"] == effect) return &s;
  return nullptr;
}

// The planted payload (datasets/sim2real/configs/payload.json: 2 kg at y = +0.12 m) is recovered
// on the left, mostly lateral, and both the projected score and the direct check (models trained
// on new re-simulations) fit the real set better than the nominal config.
TEST(Sim2RealApp, PayloadPairRecalibratesPayload) {
  const json recal = RunRecalibration("datasets/sim2real/payload/real.h5", "payload");
  const json* scan = FindScan(recal, "payload_offset");
  ASSERT_NE(scan, nullptr) << "payload_offset not selected or not scanned: " << recal.dump();
  const json& position = (*scan)["best"]["position_body_m"];
  EXPECT_GT((*scan)["best"]["mass_kg"].get<double>(), 0.0);
  EXPECT_GT(position[1].get<double>(), 0.0);  // left
  EXPECT_GT(std::abs(position[1].get<double>()), std::abs(position[0].get<double>()));
  EXPECT_GT((*scan)["improvement_nats_per_sample"].get<double>(), 0.0);
  ASSERT_TRUE(recal.contains("verification"));
  EXPECT_GT(recal["verification"]["improvement_nats_per_sample"].get<double>(), 0.0);
}

// The planted weak leg (configs/weak_leg.json: leg 1, left middle-front, at 0.3 gain) is the
// leg found, its gain within 30% of 0.3, and the recalibrated config fits the real set better.
TEST(Sim2RealApp, WeakLegPairRecalibratesLegGain) {
  const json recal = RunRecalibration("datasets/sim2real/weak_leg/real.h5", "weak-leg");
  const json* scan = FindScan(recal, "actuator_asymmetry");
  ASSERT_NE(scan, nullptr) << "actuator_asymmetry not selected or not scanned: " << recal.dump();
  ASSERT_TRUE((*scan)["best"].contains("leg")) << scan->dump();
  EXPECT_EQ((*scan)["best"]["leg"].get<int>(), 1);
  const double planted_gain = 0.3;
  EXPECT_NEAR((*scan)["best"]["gain"].get<double>(), planted_gain, kParameterTolerance * planted_gain);
  EXPECT_GT((*scan)["improvement_nats_per_sample"].get<double>(), 0.0);
  ASSERT_TRUE(recal.contains("verification"));
  EXPECT_GT(recal["verification"]["improvement_nats_per_sample"].get<double>(), 0.0);
}

// Nothing selected, nothing re-simulated: the null pair's recalibration says why it skipped.
TEST(Sim2RealApp, NullPairSkipsRecalibration) {
  const json recal = RunRecalibration("datasets/sim2real/null/real.h5", "null");
  EXPECT_TRUE(recal.contains("skipped")) << recal.dump();
  EXPECT_FALSE(recal.contains("scans"));
}

// The knob path on the shipped payload pair (2 kg at x 0, y +0.12 m): the payload is named, then
// re-simulated at the position its fit implies (on the left, mostly lateral) and its mass refined
// by simulation; the named mass is within 30% of the planted one. 26 placements per signature
// simulation (one heading per command) and a cache of its own keep it to about two minutes.
TEST(Sim2RealApp, KnobPathRefinesThePayloadBySimulation) {
  auto dir = MakeTempDir("sim2real-knob-payload");
  RunResult r = RunDgmm({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(), "--real",
                         SourcePath("datasets/sim2real/payload/real.h5").string(), "-o", (dir / "out").string(),
                         "--no-figures", "--bootstrap", "0", "--no-experiment-check", "--sim-config",
                         SourcePath("datasets/sim2real/configs/nominal.json").string(), "--signature-placements",
                         "26", "--cache", (dir / "cache").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  const json& named = j["verdict"]["named"];
  ASSERT_FALSE(named.empty()) << j["verdict"].dump();
  EXPECT_EQ(named[0]["family"], "payload") << j["verdict"].dump();
  EXPECT_NEAR(named[0]["value"].get<double>(), 2.0, kParameterTolerance * 2.0);
  int payload_simulations = 0;
  for (const auto& step : j["knob_analysis"]["refinement"]) {
    const std::string knob = step["knob"];
    double x = 0, y = 0;
    if (std::sscanf(knob.c_str(), "payload.mass_kg at (x %lf, y %lf)", &x, &y) != 2) continue;
    ++payload_simulations;
    EXPECT_GT(y, 0.0) << knob;
    EXPECT_GT(std::abs(y), std::abs(x)) << knob;
    EXPECT_GT(step["value"].get<double>(), 0.0);
  }
  EXPECT_GE(payload_simulations, 1) << j["knob_analysis"]["refinement"].dump();
}

TEST(Sim2RealApp, MissingInputIsOneLineError) {
  auto dir = MakeTempDir("sim2real-missing");
  RunResult r = RunDgmm({"sim2real", "--sim", (dir / "nope.h5").string(), "--real",
                         SourcePath("datasets/sim2real/null/real.h5").string(), "-o",
                         (dir / "out").string()});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.exit_code, -1);
  EXPECT_EQ(CountLines(r.err), 1);
}

TEST(Sim2RealApp, CorrectedModelScoresBetterThanSimModel) {
  auto dir = MakeTempDir("sim2real-score");
  const std::string real = SourcePath("datasets/sim2real/slip/real.h5").string();
  ASSERT_EQ(RunDgmm({"sim2real", "--sim", SourcePath("datasets/sim2real/sim.h5").string(), "--real",
                     real, "-o", dir.string(), "--no-figures", "--bootstrap", "0"}).exit_code, 0);
  auto score = [&](const std::string& model) {
    RunResult r = RunDgmm({"score", (dir / model).string(), real, "--json"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out)["mean_log_likelihood"].get<double>();
  };
  EXPECT_GT(score("corrected_model.h5"), score("sim_model.h5"));
}

}  // namespace
}  // namespace dgmm::test
