#include "predict/region_calibration.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "predict/episode_set.h"
#include "util/error.h"

namespace dgmm::predict {
namespace {

// Each episode's samples in step order from step 0 up to its first missing step.
std::vector<std::vector<int>> Episodes(const SampleSet& set) {
  std::map<int, std::map<int, int>> by_episode;  // episode -> step -> sample
  for (int i = 0; i < set.size(); ++i) by_episode[set.episode[i]][set.step[i]] = i;
  std::vector<std::vector<int>> out;
  for (const auto& [episode, steps] : by_episode) {
    std::vector<int> rows;
    for (int k = 0; steps.count(k) > 0; ++k) rows.push_back(steps.at(k));
    if (!rows.empty()) out.push_back(std::move(rows));
  }
  return out;
}

// q_k per level for one episode: its outcome's d2 over each level's uncalibrated r2 (horizons x levels).
Eigen::MatrixXd EpisodeRatios(const MotionModel& model, const SampleSet& set, const std::vector<int>& rows,
                              const PredictOptions& options, const std::string& source) {
  std::vector<Step> steps;
  Eigen::MatrixXd x(rows.size(), model.pose_dim);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    const int id = ModelCommandId(model, set, set.command[i], source);
    if (!model.HasCommand(id)) throw MakeInputError(source, "command", "command " + std::to_string(id) + " is not in the model");
    steps.push_back({id, model.terrain_dim > 0 ? Eigen::VectorXd(set.z.row(i).transpose()) : Eigen::VectorXd()});
    x.row(k) = set.x.row(i);
  }
  const Prediction p = Predict(model, Eigen::Vector3d::Zero(), steps, options);
  const Eigen::MatrixXd truth = ComposePath(model, Eigen::Vector3d::Zero(), x, options);
  Eigen::MatrixXd ratio(rows.size(), options.region_levels.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double d2 = p.steps[k].RegionDistance2(truth.row(k).head<2>().transpose());
    for (std::size_t l = 0; l < options.region_levels.size(); ++l) {
      ratio(k, l) = d2 / std::max(p.steps[k].region_r2[l], 1e-300);
    }
  }
  return ratio;
}

// The ceil((n + 1) level)-th smallest of v (the largest when that exceeds n).
double ConformalQuantile(std::vector<double> v, double level) {
  const auto n = static_cast<double>(v.size());
  const auto rank = static_cast<std::size_t>(std::min(n, std::ceil((n + 1) * level)));
  std::nth_element(v.begin(), v.begin() + (rank - 1), v.end());
  return v[rank - 1];
}

}  // namespace

RegionCalibration CalibrateRegions(const MotionModel& model, const SampleSet& held_out, const PredictOptions& prediction,
                                   const CalibrationOptions& options, const std::string& source) {
  PredictOptions o = prediction;
  o.calibration = {};
  if (std::string e; !o.IsValid(&e)) throw MakeInputError("calibration", "options", e);
  if (o.trajectories < 2 || options.min_episodes < 1) {
    throw MakeInputError("calibration", "options", "expected trajectories >= 2 and min_episodes >= 1");
  }
  CheckEpisodeSet(model, held_out, source, "calibration");
  const std::vector<std::vector<int>> episodes = Episodes(held_out);
  std::vector<std::vector<std::vector<double>>> ratios;  // horizon -> level -> one per episode reaching it
  for (std::size_t e = 0; e < episodes.size(); ++e) {
    o.seed = prediction.seed + 1 + e;  // every episode its own draws, the same on every run
    const Eigen::MatrixXd r = EpisodeRatios(model, held_out, episodes[e], o, source);
    if (ratios.size() < static_cast<std::size_t>(r.rows())) ratios.resize(r.rows(), std::vector<std::vector<double>>(r.cols()));
    for (Eigen::Index k = 0; k < r.rows(); ++k) {
      for (Eigen::Index l = 0; l < r.cols(); ++l) ratios[k][l].push_back(r(k, l));
    }
  }
  RegionCalibration out;
  out.levels = o.region_levels;
  for (std::size_t k = 0; k < ratios.size() && static_cast<int>(ratios[k][0].size()) >= options.min_episodes; ++k) {
    out.factor.conservativeResize(k + 1, out.levels.size());
    out.episodes.conservativeResize(k + 1);
    out.episodes[k] = static_cast<int>(ratios[k][0].size());
    for (std::size_t l = 0; l < out.levels.size(); ++l) out.factor(k, l) = ConformalQuantile(ratios[k][l], out.levels[l]);
  }
  if (out.empty()) {
    throw MakeInputError(source, "episode", "expected at least " + std::to_string(options.min_episodes) +
                                                 " episodes starting at step 0 to calibrate on, found " +
                                                 std::to_string(ratios.empty() ? 0 : ratios[0][0].size()));
  }
  // A factor of 0 (every outcome on its predicted mean) would collapse the region.
  out.factor = out.factor.cwiseMax(1e-6);
  return out;
}

}  // namespace dgmm::predict
