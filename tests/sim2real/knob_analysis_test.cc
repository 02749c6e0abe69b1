// The pieces of the simulator-knob analysis: paired signatures, the simulation cache, ties of
// collinear signatures, structured residuals, the verdict's "not computed", raw units.
#include "sim2real/knob_analysis.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <unistd.h>

#include "sim2real/residual_structure.h"
#include "sim2real/selection.h"
#include "sim2real/signatures.h"
#include "sim2real/synthetic.h"
#include "sim2real/verdict.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// A paper-protocol-like set: `episodes` placements of 5 steps, commands cycling over 3.
SampleSet MakeSet(int episodes, std::uint64_t seed) {
  SampleSet s;
  s.command_dim_names = {"long"};
  s.commands = Eigen::MatrixXd(3, 1);
  s.commands << -0.5, 0.5, 1.0;
  s.command_labels = {"a", "b", "c"};
  const int n = 5 * episodes;
  s.command.resize(n);
  s.episode.resize(n);
  s.step.resize(n);
  s.x.resize(n, 2);
  s.z.resize(n, 2);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  for (int i = 0; i < n; ++i) {
    s.episode(i) = i / 5;
    s.step(i) = i % 5;
    s.command(i) = (i / 5) % 3;
    s.z(i, 0) = 0.3 * std::sin(i / 5);
    s.z(i, 1) = 0.3 * std::cos(i / 5);
    s.x(i, 0) = 0.1 * s.command(i) + 0.01 * unit(rng);
    s.x(i, 1) = 0.01 * unit(rng);
  }
  s.x_names = {"dx", "dy"};
  s.z_names = {"pitch", "roll"};
  return s;
}

TEST(PairedShift, RecoversAPlantedShiftLinearInTerrain) {
  const SampleSet nominal = MakeSet(30, 1);
  SampleSet perturbed = nominal;
  for (int i = 0; i < perturbed.size(); ++i) {
    perturbed.x(i, 0) += 0.02 * (perturbed.command(i) + 1) + 0.05 * perturbed.z(i, 0);
    perturbed.x(i, 1) -= 0.01;
  }
  const PairedShift shift = PairedShift::Fit(nominal, perturbed, nominal, 0.0);
  EXPECT_EQ(shift.pairs(), nominal.size());
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector2d z(0.2, -0.1);
    const Eigen::VectorXd s = shift.Shift(c, z, 0.0);
    EXPECT_NEAR(s(0), 0.02 * (c + 1) + 0.05 * 0.2, 1e-6);
    EXPECT_NEAR(s(1), -0.01, 1e-6);
  }
  EXPECT_NEAR(shift.log_variance_ratio()(1), 0.0, 1e-9);  // a pure shift leaves the spread alone
}

TEST(SimulationCache, SecondRequestIsReadBackIdentical) {
  const auto dir = std::filesystem::temp_directory_path() / ("dgmm_knob_cache_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  sim::SimConfig config;
  const std::vector<sim::Knob> knobs = sim::EnumerateKnobs(config);
  SignatureOptions options;
  options.placements = 3;  // one command, three headings: fast
  options.cache_dir = dir.string();
  std::vector<SimulationRequest> requests(2);
  requests[1].values = {{0, 0.6}};
  const SimulationBatch first = SimulateBatch(config, sim::Protocol::kPaper, 7, knobs, requests, options);
  EXPECT_EQ(first.simulated, 2);
  const SimulationBatch second = SimulateBatch(config, sim::Protocol::kPaper, 7, knobs, requests, options);
  EXPECT_EQ(second.from_cache, 2);
  EXPECT_EQ(second.simulated, 0);
  for (int r = 0; r < 2; ++r) {
    ASSERT_EQ(first.sets[r].size(), second.sets[r].size());
    EXPECT_TRUE(first.sets[r].x.isApprox(second.sets[r].x, 0.0) || first.sets[r].x == second.sets[r].x);
  }
  // The key depends on the knob value: another value is a different entry.
  EXPECT_NE(SimulationKey(config, sim::Protocol::kPaper, 7, 3, knobs, {{0, 0.6}}),
            SimulationKey(config, sim::Protocol::kPaper, 7, 3, knobs, {{0, 0.7}}));
  std::filesystem::remove_all(dir);
}

// Fills the sim-side fields of `fp` (whitened designs = designs, unit log-normaliser) with real
// residuals r0 = shift(i, j) + N(0, 1), episodes of 5 samples and 3 commands; returns the rows
// 0..n-1 and their 5 episode folds in *fold.
template <typename Shift>
std::vector<int> FillResidualsAndFolds(FitProblem* fp, Shift shift, std::uint64_t seed, std::vector<int>* fold) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  fp->g = fp->d;
  fp->r0.resize(fp->n, fp->dx);
  fp->log_norm = Eigen::VectorXd::Constant(fp->n, -fp->dx * 0.5 * std::log(2 * M_PI));
  for (int i = 0; i < fp->n; ++i) {
    for (int j = 0; j < fp->dx; ++j) fp->r0(i, j) = shift(i, j) + unit(rng);
    fp->episode.push_back(i / 5);
    fp->command.push_back(i % 3);
  }
  std::vector<int> rows(fp->n);
  for (int i = 0; i < fp->n; ++i) rows[i] = i;
  std::mt19937_64 frng(1);
  *fold = MakeFolds(*fp, rows, 5, frng);
  return rows;
}

// Two candidates with the same design (perfectly collinear signatures) from different families
// must be reported as a tie; a third, orthogonal one must not.
TEST(TiedCandidates, CollinearSignaturesTie) {
  const int n = 300, dx = 2;
  FitProblem fp;
  fp.n = n;
  fp.dx = dx;
  Eigen::MatrixXd d1(n * dx, 1), d3(n * dx, 1);
  for (int i = 0; i < n; ++i) {
    d1(i * dx) = 1.0 + 0.5 * std::sin(i);
    d1(i * dx + 1) = 0.3;
    d3(i * dx) = 0.0;
    d3(i * dx + 1) = std::cos(3.0 * i);
  }
  for (int k = 0; k < 3; ++k) {
    EffectSpec s;
    s.id = EffectId::kExternal;
    s.key = "e" + std::to_string(k);
    s.parameters = {{"t", ""}};
    fp.library.push_back(s);
  }
  fp.d = {d1, d1, d3};
  std::vector<int> fold;
  const std::vector<int> rows =
      FillResidualsAndFolds(&fp, [&](int i, int j) { return 0.8 * d1(i * dx + j); }, 3, &fold);
  SelectionOptions so;
  so.bootstrap_selection = 0;
  const SelectionResult sel = ForwardSelect(fp, rows, fold, so);
  ASSERT_FALSE(sel.selected.empty());
  const int chosen = sel.selected[0];
  ASSERT_NE(chosen, 2);
  std::vector<double> corr;
  const std::vector<int> tied = TiedCandidates(fp, sel.steps[0], chosen, {"friction", "payload", "contact"}, 0.9,
                                               so.fit, &corr);
  ASSERT_EQ(tied.size(), 1u);
  EXPECT_EQ(tied[0], chosen == 0 ? 1 : 0);
  EXPECT_NEAR(corr[0], 1.0, 1e-6);
  // The same family is never a tie with itself.
  EXPECT_TRUE(TiedCandidates(fp, sel.steps[0], chosen, {"friction", "friction", "contact"}, 0.9, so.fit).empty());
}

// Two mean shifts, each too weak alone to beat a wider variance: forward selection takes noise
// first, then both shifts; the backward pass drops the noise again (the residual left by the two
// shifts has the simulated scale), and keeps both shifts.
TEST(ForwardSelect, BackwardPassDropsNoiseThatOnlyStoodInForMissingShifts) {
  const int n = 400, dx = 2;
  FitProblem fp;
  fp.n = n;
  fp.dx = dx;
  Eigen::MatrixXd d1 = Eigen::MatrixXd::Zero(n * dx, 1), d2 = Eigen::MatrixXd::Zero(n * dx, 1);
  for (int i = 0; i < n; ++i) {
    d1(i * dx) = (i % 2 ? 1.0 : -1.0);
    d2(i * dx + 1) = ((i / 2) % 2 ? 1.0 : -1.0);
  }
  EffectSpec noise;
  noise.id = EffectId::kNoise;
  noise.key = "noise";
  noise.is_noise = true;
  noise.parameters = {{"log_tau", ""}};
  fp.library.push_back(noise);
  for (int k = 1; k <= 2; ++k) {
    EffectSpec s;
    s.id = EffectId::kExternal;
    s.key = "e" + std::to_string(k);
    s.parameters = {{"t", ""}};
    fp.library.push_back(s);
  }
  fp.d = {Eigen::MatrixXd::Zero(n * dx, 1), d1, d2};
  std::vector<int> fold;
  const std::vector<int> rows = FillResidualsAndFolds(
      &fp, [&](int i, int j) { return 2.5 * d1(i * dx + j) + 2.5 * d2(i * dx + j); }, 5, &fold);
  SelectionOptions so;
  so.bootstrap_selection = 0;
  const SelectionResult forward = ForwardSelect(fp, rows, fold, so);
  ASSERT_FALSE(forward.steps.empty());
  ASSERT_EQ(forward.steps[0].chosen, 0) << "the case needs noise to win the first step";
  EXPECT_EQ(forward.selected.size(), 3u);
  so.backward = true;
  const SelectionResult both = ForwardSelect(fp, rows, fold, so);
  EXPECT_EQ(both.removed, std::vector<int>{0});
  std::vector<int> kept = both.selected;
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, (std::vector<int>{1, 2}));
  EXPECT_NEAR(both.fit.log_tau, 0.0, 0.15);
  EXPECT_GE(both.heldout_corrected.mean(), forward.heldout_corrected.mean() - 0.01);
}

// Residuals with a step-periodic offset (alternating sign along the five executions of each
// placement) are structured, in "step" and "periodic"; plain Gaussian residuals are not.
TEST(ResidualStructure, PeriodicStepOffsetIsStructuredNoiseIsNot) {
  const int episodes = 78, n = 5 * episodes, dx = 3;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit(0, 1);
  Eigen::MatrixXd r(n, dx);
  std::vector<int> command(n), terrain(n), episode(n), step(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < dx; ++j) r(i, j) = unit(rng);
    episode[i] = i / 5;
    step[i] = i % 5;
    command[i] = (i / 5) % 26;
    terrain[i] = (i / 5) % 3;
  }
  ResidualStructureOptions options;
  const ResidualStructure clean = TestResidualStructure(r, command, terrain, episode, step, ExcessKurtosis(r), options, 1);
  EXPECT_TRUE(clean.structured_in.empty());
  for (int i = 0; i < n; ++i) r(i, 1) += (step[i] % 2 == 0 ? 0.6 : -0.6);
  const ResidualStructure periodic = TestResidualStructure(r, command, terrain, episode, step, 0.0, options, 1);
  auto has = [&](const std::string& w) {
    return std::find(periodic.structured_in.begin(), periodic.structured_in.end(), w) != periodic.structured_in.end();
  };
  EXPECT_TRUE(has("step"));
  EXPECT_TRUE(has("periodic"));
  EXPECT_FALSE(has("command"));
}

TEST(Verdict, BootstrapOffWritesNullInclusionAndNotComputed) {
  SyntheticWorld w;
  w.slip_creep = 0.05;
  const SampleSet sim = GenerateSynthetic(SyntheticWorld{}, "paper-830", 21);
  const SampleSet real = GenerateSynthetic(w, "paper", 1021);
  Sim2RealOptions options;
  options.selection.bootstrap_selection = 0;
  options.selection.bootstrap_parameters = 20;
  options.locate.mmd.permutations = 100;
  const Sim2RealResult r = RunSim2Real(sim, real, options);
  ASSERT_FALSE(r.effects.empty());
  EXPECT_NE(r.conclusion.find("not computed"), std::string::npos) << r.conclusion;
  EXPECT_EQ(r.conclusion.find("[inclusion 0%]"), std::string::npos);
  const Verdict v = VerdictFromEffects(r);
  const auto j = nlohmann::json::parse(VerdictJson(v));
  ASSERT_FALSE(j["named"].empty());
  EXPECT_TRUE(j["named"][0]["inclusion"].is_null());
  EXPECT_EQ(j["named"][0]["family"], "friction");
  EXPECT_TRUE(j["status"] == "explained" || j["status"] == "partly_explained");
}

TEST(Verdict, DriftingEffectsAreWrittenApartFromTheNamedOnes) {
  Verdict v;
  v.status = "unexplained";
  VerdictDrifting d;
  d.family = "actuator_gain", d.knob = "actuators.kp_scale", d.value = 0.72, d.nominal = 1.0;
  d.first = 0.95, d.last = 0.49, d.gamma = 1.4, d.p_value = 0.001;
  v.drifting.push_back(d);
  d.along = "execution index", d.family = "tracker_bias", d.first = -0.01, d.last = 0.03, d.first_step = 1, d.last_step = 3;
  v.drifting.push_back(d);
  v.structured_in = {"session order"};
  const auto j = nlohmann::json::parse(VerdictJson(v));
  EXPECT_TRUE(j["named"].empty());
  ASSERT_EQ(j["drifting"].size(), 2u);
  EXPECT_EQ(j["drifting"][0]["along"], "session order");
  EXPECT_EQ(j["drifting"][1]["along"], "execution index");
  EXPECT_DOUBLE_EQ(j["drifting"][1]["highest"].get<double>(), 0.03);
  EXPECT_EQ(j["drifting"][1]["lowest_step"], 1);
  EXPECT_FALSE(j["drifting"][1].contains("first"));
  EXPECT_EQ(j["drifting"][0]["family"], "actuator_gain");
  EXPECT_DOUBLE_EQ(j["drifting"][0]["first"].get<double>(), 0.95);
  EXPECT_DOUBLE_EQ(j["drifting"][0]["last"].get<double>(), 0.49);
  EXPECT_DOUBLE_EQ(j["drifting"][0]["relative_change"].get<double>(), 1.4);
  EXPECT_TRUE(j["drifting"][0]["inclusion"].is_null());
  EXPECT_EQ(j["unexplained"]["structured_in"][0], "session order");
}

TEST(RawUnits, UndoesTheTransformAndRefusesAMismatchedOne) {
  SampleSet s = MakeSet(4, 2);
  SampleSet standardised = s;
  standardised.transform.offset = Eigen::VectorXd::Constant(4, 1.0);
  standardised.transform.scale = Eigen::VectorXd::Constant(4, 2.0);
  const SampleSet raw = ToRawUnits(standardised, "--real");
  EXPECT_TRUE(raw.transform.empty());
  EXPECT_NEAR(raw.x(3, 0), 1.0 + 2.0 * s.x(3, 0), 1e-12);
  EXPECT_NEAR(raw.z(2, 1), 1.0 + 2.0 * s.z(2, 1), 1e-12);
  standardised.transform.scale = Eigen::VectorXd::Constant(3, 2.0);
  EXPECT_THROW(ToRawUnits(standardised, "--real"), InputError);
}

}  // namespace
}  // namespace dgmm::sim2real

namespace dgmm::sim2real {
namespace {

TEST(OnlyEffects, RestrictsTheLibraryAndRejectsUnknownKeys) {
  const SampleSet sim = GenerateSynthetic(SyntheticWorld{}, "paper-830", 31);
  const SampleSet real = GenerateSynthetic(SyntheticWorld{}, "paper", 1031);
  Sim2RealOptions options;
  options.selection.bootstrap_selection = 0;
  options.selection.bootstrap_parameters = 10;
  options.locate.mmd.permutations = 50;
  options.only_effects = {"bias", "noise"};
  const Sim2RealResult r = RunSim2Real(sim, real, options);
  ASSERT_EQ(r.library.size(), 2u);
  for (const auto& e : r.library) EXPECT_TRUE(e.key == "bias" || e.key == "noise");
  options.only_effects = {"slip"};
  EXPECT_THROW(RunSim2Real(sim, real, options), InputError);
}

}  // namespace
}  // namespace dgmm::sim2real
