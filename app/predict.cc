// `dgmm predict`: where a sequence of commands takes the robot, with how sure the model is: the
// pose distribution after each command (lib/predict/predict.h), as JSON and a table.
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <fstream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/command.h"
#include "app/wiring/ground_surface.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "predict/ground_terrain.h"
#include "predict/predict.h"
#include "predict/region_calibration.h"
#include "render/display.h"
#include "sim/sim_config.h"
#include "render/trajectory_fan.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct PredictArgs {
  std::string model, commands, terrain, command_values, output, pose_dims, figure, ground, persistence, calibrate;
  std::vector<double> start{0, 0, 0};
  bool walking = false;
  int trajectories = 1000;
  std::uint64_t seed = 1;
};

std::vector<std::string> SplitOn(const std::string& text, char separator) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, separator);) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// Command labels separated by ';' (labels themselves contain commas), each optionally "label*N".
std::vector<int> ParseCommands(const MotionModel& model, const std::string& text) {
  std::vector<int> ids;
  for (const std::string& item : SplitOn(text, ';')) {
    const auto star = item.rfind('*');
    const std::string label = star == std::string::npos ? item : item.substr(0, star);
    const int times = star == std::string::npos ? 1 : std::atoi(item.c_str() + star + 1);
    int id = -1;
    for (const auto& [c, l] : model.command_labels) {
      if (l == label) id = c;
    }
    if (id < 0) throw MakeInputError("--commands", label, "the model has no command with this label (dgmm info lists them)");
    if (times < 1 || times > 10000) throw MakeInputError("--commands", item, "expected label*N with N in 1..10000");
    ids.insert(ids.end(), times, id);
  }
  if (ids.empty()) throw MakeInputError("--commands", "", "expected at least one command label");
  return ids;
}

// "pitch=0.1,roll=0" by the model's terrain names; with `partial` the dimensions not named stay NaN
// (read off the ground).
Eigen::VectorXd ParseOneTerrain(const MotionModel& model, const std::string& text, bool partial = false) {
  if (text.empty()) return {};
  if (model.terrain_dim == 0) throw MakeInputError("--terrain", "", "the model was fitted without terrain");
  Eigen::VectorXd z = Eigen::VectorXd::Constant(model.terrain_dim, NAN);
  for (const std::string& item : SplitOn(text, ',')) {
    const auto eq = item.find('=');
    const std::string name = item.substr(0, eq);
    int d = -1;
    for (int i = 0; i < model.terrain_dim; ++i) {
      if (model.terrain_names[i] == name) d = i;
    }
    if (eq == std::string::npos || d < 0) {
      throw MakeInputError("--terrain", item, "expected name=value with a terrain (or continuous command) name of the model");
    }
    char* end = nullptr;
    z[d] = std::strtod(item.c_str() + eq + 1, &end);
    if (end == item.c_str() + eq + 1 || *end != '\0') throw MakeInputError("--terrain", item, "expected a number after '='");
  }
  if (!partial && !z.allFinite()) {
    std::string missing;
    for (int i = 0; i < model.terrain_dim; ++i) {
      if (!std::isfinite(z[i])) missing += (missing.empty() ? "" : ",") + model.terrain_names[i];
    }
    throw MakeInputError("--terrain", text, "expected a value for every conditioning dimension; missing " + missing);
  }
  return z;
}

// One entry per step of a ';'-separated list: one entry for all, or one per step (after
// label*N expansion); none when the text is empty.
std::vector<std::string> PerStep(const std::string& text, std::size_t steps, const char* flag, const char* what) {
  const std::vector<std::string> items = SplitOn(text, ';');
  if (items.size() > 1 && items.size() != steps) {
    throw MakeInputError(flag, "", std::to_string(items.size()) + " " + what + " for " + std::to_string(steps) +
                                       " commands: expected one for all or one per command");
  }
  std::vector<std::string> out;
  for (std::size_t k = 0; k < steps && !items.empty(); ++k) out.push_back(items[items.size() == 1 ? 0 : k]);
  return out;
}

// The conditioning value of every step: the continuous command values (--command-values) and the
// terrain (--terrain), both by the model's z names and merged per step. Nothing given: the
// terrain marginalised.
std::vector<Eigen::VectorXd> ParseTerrain(const MotionModel& model, const std::string& terrain,
                                          const std::string& command_values, std::size_t steps, bool partial) {
  const std::vector<std::string> t = PerStep(terrain, steps, "--terrain", "terrains");
  const std::vector<std::string> c = PerStep(command_values, steps, "--command-values", "command values");
  std::vector<Eigen::VectorXd> z(steps);
  for (std::size_t k = 0; k < steps; ++k) {
    std::string merged = c.empty() ? "" : c[k];
    if (!t.empty() && !t[k].empty()) merged += (merged.empty() ? "" : ",") + t[k];
    z[k] = ParseOneTerrain(model, merged, partial);
  }
  return z;
}

// The conditioning dimensions some step gives a value for (continuous command values with
// --ground): they are not read off the ground.
std::vector<std::string> GivenNames(const MotionModel& model, const std::vector<Eigen::VectorXd>& z) {
  std::vector<std::string> names;
  for (int d = 0; d < model.terrain_dim; ++d) {
    for (const Eigen::VectorXd& step : z) {
      if (step.size() > 0 && std::isfinite(step[d])) {
        names.push_back(model.terrain_names[d]);
        break;
      }
    }
  }
  return names;
}

// A step's planar regions: share and r2 of {p : (p - m)^T C^-1 (p - m) <= r2}, m and C the mean and
// covariance of x, y.
nlohmann::json Regions(const predict::StepPrediction& s) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t l = 0; l < s.region_levels.size(); ++l) {
    out.push_back({{"share", s.region_levels[l]}, {"r2", s.region_r2[l]}});
  }
  return out;
}

nlohmann::json ToJson(const MotionModel& model, const std::vector<int>& ids, const predict::Prediction& p,
                      const PredictArgs& args) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t k = 0; k < p.steps.size(); ++k) {
    const auto& s = p.steps[k];
    std::vector<std::vector<double>> cov(4, std::vector<double>(4));
    for (int r = 0; r < 4; ++r) for (int c = 0; c < 4; ++c) cov[r][c] = s.covariance(r, c);
    steps.push_back({{"step", k + 1},
                     {"command", model.command_labels.at(ids[k])},
                     {"mean", {s.mean[0], s.mean[1], s.mean[2], s.mean[3]}},
                     {"covariance", cov},
                     {"regions", Regions(s)}});
  }
  return {{"model", args.model}, {"pose", {"x_m", "y_m", "z_m", "yaw_rad"}}, {"spatial", p.spatial},
          {"start", args.start}, {"trajectories", args.trajectories}, {"seed", args.seed},
          {"terrain", args.terrain}, {"command_values", args.command_values}, {"persistence_from", args.persistence},
          {"calibrated_from", args.calibrate}, {"steps", steps}};
}

// The trajectory fan (render/trajectory_fan.h) of the prediction, written to args.figure.
void WriteFigure(const predict::Prediction& p, const PredictArgs& args,
                 const std::function<double(double, double)>& ground_height) {
  std::vector<Eigen::MatrixX2d> steps;
  std::vector<std::vector<double>> r2;
  for (const auto& s : p.steps) steps.push_back(s.poses.leftCols(2)), r2.push_back(s.region_r2);
  const std::string title = "Where " + std::to_string(p.steps.size()) + " commands take the robot (" +
                            std::to_string(args.trajectories) + " trajectories): 50% (white) and 90% (orange) regions" +
                            (args.calibrate.empty() ? "" : ", calibrated");
  HeatMapSpec fan = TrajectoryFan(steps, Eigen::Vector2d(args.start[0], args.start[1]), title, r2);
  if (ground_height) fan.contours.push_back(GroundContours(fan.background.range, ground_height));
  RenderHeatMap(fan, args.figure);
}

// One warning line per step whose conditioning value (terrain, continuous commands) lies where
// the training data are thin: fewer than 1% of the samples near it that lie near the densest
// point of the data (MotionModel::SamplesNear): the prediction extrapolates there.
void WarnWhereDataIsThin(const MotionModel& model, const std::vector<int>& ids,
                         const std::vector<Eigen::VectorXd>& z) {
  constexpr double kThin = 0.01;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (z[k].size() == 0 || !z[k].allFinite()) continue;  // read off the ground per trajectory
    double at_data = 0;
    const double near = model.SamplesNear(ids[k], z[k], &at_data);
    if (near >= kThin * at_data) continue;
    std::string at;
    for (int j = 0; j < model.terrain_dim; ++j) {
      at += fmt::format("{}{}={:g}", j ? "," : "", model.terrain_names[j], z[k][j]);
    }
    std::fprintf(stderr,
                 "dgmm: warning: predict: step %zu: %s is outside what command '%s' was trained "
                 "on (about %.2g training samples near it, %.2g near the densest data; kernel of "
                 "0.1 standard deviation per dimension): the prediction extrapolates\n",
                 k + 1, at.c_str(), model.command_labels.at(ids[k]).c_str(), near, at_data);
  }
}

// A height field is finite: trajectories that leave it read its edge heights.
void WarnOffTheField(const predict::Prediction& p, const sim::TerrainDescription& terrain, const std::string& file) {
  for (std::size_t k = 0; k < p.steps.size(); ++k) {
    const Eigen::MatrixXd& poses = p.steps[k].poses;
    const auto off = (poses.leftCols(2).array().abs() > terrain.half_size_m).rowwise().any().count();
    if (off == 0) continue;
    std::fprintf(stderr,
                 "dgmm: warning: predict: %s: %ld of %ld trajectories leave the height field "
                 "(+-%g m) by step %zu; beyond it the ground's edge heights are used\n",
                 file.c_str(), static_cast<long>(off), static_cast<long>(poses.rows()), terrain.half_size_m, k + 1);
    return;
  }
}

// The persistence of deviations estimated from the episodes of `path`, one line per pose dimension.
predict::StepPersistence PersistenceFrom(const MotionModel& model, const std::string& path) {
  const predict::PersistenceSummary s = predict::EstimatePersistence(model, ReadSampleSet(path), {}, path);
  // On the sets a model was learnt from the RMS is 0.4 to 1 (its covariances carry a prior).
  if (s.residual_rms.maxCoeff() > 2.5) {
    std::fprintf(stderr,
                 "dgmm: warning: predict: %s: its deviations from the model reach %.2g times the model's own "
                 "spread (RMS of standardised residuals, largest pose dimension; at most about 1 on the set the "
                 "model was learnt from): the persistence estimated from it describes another robot or ground\n",
                 path.c_str(), s.residual_rms.maxCoeff());
  }
  std::printf("persistence from %s (%d episodes; %d pairs of consecutive steps; %d first steps): corr(step t, t + l) "
              "= a phi^l; the first command's spread from standing relative to the model's\n",
              path.c_str(), s.episodes, s.pairs[0], s.first_steps);
  for (int d = 0; d < model.pose_dim; ++d) {
    std::printf("  %-8s a = %.2f  phi = %.2f  (lag 1: %+.2f)  first step from standing x%.2f\n",
                model.pose_names[d].c_str(), s.persistence.shared[d], s.persistence.decay[d], s.lag_correlation(d, 0),
                s.persistence.first_scale[d]);
  }
  return s.persistence;
}

// The regions' factors from the held-out episodes of `path`, printed one line per horizon.
predict::RegionCalibration CalibrationFrom(const MotionModel& model, const std::string& path,
                                           const predict::PredictOptions& options) {
  const predict::RegionCalibration c = predict::CalibrateRegions(model, ReadSampleSet(path), options, {}, path);
  std::printf("regions calibrated on %s: r2 of the 50%% and 90%% regions times (held-out episodes)\n", path.c_str());
  for (Eigen::Index k = 0; k < c.factor.rows(); ++k) {
    std::printf("  after %2ld commands  x%.2f  x%.2f  (%d episodes)\n", static_cast<long>(k + 1), c.factor(k, 0),
                c.factor(k, 1), c.episodes[k]);
  }
  return c;
}

void Run(const PredictArgs& args) {
  if (!args.figure.empty()) RequireDisplay();  // before any work or output
  for (const std::string& out : {args.output, args.figure}) {
    if (!out.empty()) AtomicFile probe(out);  // fail before the work when an output is unwritable
  }
  const MotionModel model = ReadModel(args.model);
  const std::vector<int> ids = ParseCommands(model, args.commands);
  const std::vector<Eigen::VectorXd> z =
      ParseTerrain(model, args.terrain, args.command_values, ids.size(), !args.ground.empty());
  std::vector<predict::Step> steps;
  for (std::size_t k = 0; k < ids.size(); ++k) steps.push_back({ids[k], z[k]});
  WarnWhereDataIsThin(model, ids, z);
  predict::PredictOptions options;
  options.trajectories = args.trajectories;
  options.seed = args.seed;
  options.pose_dims = SplitOn(args.pose_dims, ',');
  if (!args.persistence.empty()) options.persistence = PersistenceFrom(model, args.persistence);
  options.from_rest = !args.walking;
  if (!args.calibrate.empty()) {
    options.calibration = CalibrationFrom(model, args.calibrate, options);
    if (options.calibration.factor.rows() < static_cast<Eigen::Index>(ids.size())) {
      std::fprintf(stderr, "dgmm: warning: predict: %s: its episodes calibrate %ld commands; later steps take the "
                           "factors of the last\n", args.calibrate.c_str(), static_cast<long>(options.calibration.factor.rows()));
    }
  }
  std::optional<sim::SimConfig> ground;
  predict::GroundSurface surface;
  if (!args.ground.empty()) {
    if (!args.terrain.empty()) throw MakeInputError("--ground", "", "give either --terrain or --ground, not both");
    ground = sim::LoadSimConfig(args.ground);
    surface = GroundSurfaceOf(*ground);
    options.ground = predict::GroundTerrain(model, surface, GivenNames(model, z));
  }
  const auto p = predict::Predict(model, Eigen::Vector3d(args.start[0], args.start[1], args.start[2]), steps, options);
  if (ground && ground->terrain) WarnOffTheField(p, *ground->terrain, args.ground);
  if (!args.figure.empty()) WriteFigure(p, args, surface.height);
  if (!args.output.empty()) {
    AtomicFile file(args.output);
    std::ofstream(file.temp_path()) << ToJson(model, ids, p, args).dump(2) << "\n";
    file.Commit();
  }
  std::printf("%s trajectories, seed %llu%s\n", std::to_string(args.trajectories).c_str(),
              static_cast<unsigned long long>(args.seed),
              !args.ground.empty() ? ", terrain from the ground under each trajectory"
              : args.terrain.empty() ? ", terrain marginalised" : "");
  std::printf("step  command            mean x (m)  mean y (m)  yaw (deg)   sd x (m)  sd y (m)  sd yaw (deg)\n");
  for (std::size_t k = 0; k < p.steps.size(); ++k) {
    const auto& s = p.steps[k];
    std::printf("%4zu  %-17s %11.3f %11.3f %10.1f %10.3f %9.3f %13.1f\n", k + 1, model.command_labels.at(ids[k]).c_str(),
                s.mean[0], s.mean[1], s.mean[3] * 180 / M_PI, std::sqrt(s.covariance(0, 0)),
                std::sqrt(s.covariance(1, 1)), std::sqrt(s.covariance(3, 3)) * 180 / M_PI);
  }
  if (!args.output.empty()) std::printf("wrote %s\n", args.output.c_str());
  if (!args.figure.empty()) std::printf("wrote %s\n", args.figure.c_str());
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<PredictArgs>();
  CLI::App* cmd = root.add_subcommand(
      "predict",
      "Where a sequence of commands takes the robot: draws pose changes from p(x | c, z) for each "
      "command in turn and composes them in the robot's frame (SE(2), or SE(3) when the model has "
      "dz, droll and dpitch), giving the mean and covariance of x, y, z and yaw after every command. "
      "Seeded and repeatable.");
  cmd->add_option("model", args->model, "model file (.h5)")->required();
  cmd->add_option("--commands", args->commands,
                  "command labels separated by ';', each optionally repeated as label*N, e.g. "
                  "\"+0.5,0,0*3;0,0,+0.5\"")
      ->required();
  cmd->add_option("--terrain", args->terrain, "terrain to condition on, e.g. pitch=0.1,roll=0 for every command, or one per command separated by ';' "
                  "(default: marginalised)");
  cmd->add_option("--command-values", args->command_values,
                  "continuous command values by name (a model fitted on continuous commands, e.g. "
                  "dgmm import-log --continuous-cols), e.g. vx=0.3,wz=0.1 for every command or one "
                  "per command separated by ';'; merged with --terrain");
  cmd->add_option("--ground", args->ground,
                  "simulation config whose ground the robot walks on (its slope_deg and terrain block): each trajectory is "
                  "conditioned on the terrain where it stands (pitch and roll of the ground under its feet, and "
                  "foot_relief / height_ahead when the model has them); --start is then x, y in the slope frame "
                  "and the heading on the slope (0 = uphill)");
  cmd->add_option("--persistence", args->persistence,
                  "sample set with recorded episodes (e.g. the training set of dgmm simulate --protocol "
                  "trajectories): how the robot's deviations from the model carry over to the next commands is "
                  "estimated from it and each trajectory's draws are correlated accordingly (default: every "
                  "command drawn independently, which under-states the spread after many commands when "
                  "deviations persist)");
  cmd->add_option("--calibrate", args->calibrate,
                  "sample set of held-out episodes the model did not learn from, recorded like the sequences to "
                  "predict (e.g. dgmm simulate --protocol trajectories with another seed): each episode's commands "
                  "are predicted on its recorded terrain with the same options, and the 50% and 90% regions of "
                  "every step are widened (or narrowed) so that they hold those shares of the episodes' outcomes "
                  "after as many commands (split conformal prediction; default: the regions hold those shares of "
                  "the trajectories)");
  cmd->add_flag("--walking", args->walking,
               "the robot is already walking before the first command (with --persistence: the first command's "
               "spread is the model's, not that of a start from standing)");
  cmd->add_option("--figure", args->figure,
                  "trajectory fan (PNG): where the trajectories are after each command, each step's 50% and 90% "
                  "regions and the mean path (needs an X display, e.g. xvfb-run -a)");
  cmd->add_option("--start", args->start, "start pose x,y,yaw (m, m, rad)")->delimiter(',')->expected(3);
  cmd->add_option("--trajectories", args->trajectories, "Monte Carlo trajectories")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000000));
  cmd->add_option("--seed", args->seed, "random seed")->capture_default_str();
  cmd->add_option("--pose-dims", args->pose_dims,
                  "the model's pose-change names for dx,dy,dyaw[,dz,droll,dpitch] (default: those names)");
  cmd->add_option("-o,--output", args->output,
                  "JSON file with every step's mean, covariance and regions (share, r2 of the ellipse "
                  "(p - mean)^T C^-1 (p - mean) <= r2 in x, y)");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("predict", Setup);
}  // namespace dgmm::app
