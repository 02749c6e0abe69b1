#include "sim2real/corrected_model.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace dgmm::sim2real {
namespace {

// Corrected mean at terrain z for command c, first executions weighted by `first` in [0, 1].
Eigen::VectorXd CorrectedMean(const Sim2RealResult& r, int c, const Eigen::VectorXd& z,
                              int pitch_col, int roll_col, bool with_effects, double first) {
  Prediction p = r.sim_model.Predict(c, z, first);
  if (!with_effects) return p.mean;
  const double pitch = pitch_col >= 0 ? z(pitch_col) : 0.0, roll = roll_col >= 0 ? z(roll_col) : 0.0;
  Eigen::Vector3d g(std::sin(pitch), -std::sin(roll) * std::cos(pitch), -std::cos(roll) * std::cos(pitch));
  Eigen::VectorXd mean = p.mean;
  for (size_t k = 0; k < r.fit.effects.size(); ++k) {
    const EffectSpec& e = r.library[r.fit.effects[k]];
    if (e.is_noise) continue;
    const Eigen::VectorXd u_first = r.sim_model.Predict(c, z, 1.0).mean;
    const Eigen::VectorXd u_repeat = r.sim_model.Predict(c, z, 0.0).mean;
    Eigen::VectorXd shift_first = EffectDesign(e, r.layout, u_first, g, true) * r.fit.theta[k];
    Eigen::VectorXd shift_repeat = EffectDesign(e, r.layout, u_repeat, g, false) * r.fit.theta[k];
    mean += first * shift_first + (1 - first) * shift_repeat;
  }
  return mean;
}

MotionModel Build(const Sim2RealResult& r, const SampleSet& sim, bool corrected) {
  MotionModel m;
  m.kind = corrected ? "corrected" : "sim2real-sim";
  m.pose_dim = sim.pose_dim();
  m.terrain_dim = sim.terrain_dim();
  m.pose_names = sim.x_names;
  m.pose_units = sim.x_units;
  m.terrain_names = sim.z_names;
  m.command_dim_names = sim.command_dim_names;
  m.transform = sim.transform;
  int pitch_col, roll_col;
  DetectTerrainColumns(sim, &pitch_col, &roll_col);
  const int dx = m.pose_dim, dz = m.terrain_dim;
  const double tau2 = corrected ? std::exp(2 * r.fit.log_tau) : 1.0;
  const double share = r.sim_model.uses_sequence() || corrected ? r.first_execution_share : 0.0;
  nlohmann::json effects = nlohmann::json::array();
  if (corrected) {
    for (size_t k = 0; k < r.fit.effects.size(); ++k) {
      const EffectSpec& e = r.library[r.fit.effects[k]];
      nlohmann::json j = {{"effect", e.key}, {"theta", std::vector<double>(r.fit.theta[k].data(),
                                                 r.fit.theta[k].data() + r.fit.theta[k].size())}};
      effects.push_back(j);
    }
  }
  m.metadata["sim2real_effects"] = effects.dump();
  m.metadata["sim2real_note"] =
      "one joint Gaussian per command; effects projected linearly in z; sequence effects averaged "
      "(first-execution share " + std::to_string(r.first_execution_share) + ")";
  for (int c : r.sim_model.Commands()) {
    if (c < sim.num_commands()) {
      m.command_values[c] = sim.commands.row(c).transpose();
      if (c < static_cast<int>(sim.command_labels.size())) m.command_labels[c] = sim.command_labels[c];
    }
    const Eigen::VectorXd mz = r.sim_model.TerrainMean(c);
    const Eigen::MatrixXd sz = r.sim_model.TerrainCovariance(c);
    Prediction at_mean = r.sim_model.Predict(c, mz, r.first_execution_share);
    Eigen::MatrixXd sigma = tau2 * at_mean.chol * at_mean.chol.transpose();
    // Mixing first and repeated executions adds share (1 - share) d d^T, d = their mean difference.
    const Eigen::VectorXd d = CorrectedMean(r, c, mz, pitch_col, roll_col, corrected, 1.0) -
                              CorrectedMean(r, c, mz, pitch_col, roll_col, corrected, 0.0);
    sigma += share * (1 - share) * d * d.transpose();
    // Least-squares linear map z -> mean over points spread across the command's terrain.
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(dx, dz);
    Eigen::VectorXd mean_x = CorrectedMean(r, c, mz, pitch_col, roll_col, corrected, share);
    if (dz > 0) {
      Eigen::LLT<Eigen::MatrixXd> llt(sz);
      Eigen::MatrixXd lz = llt.matrixL();
      std::vector<Eigen::VectorXd> pts = {mz};
      for (int j = 0; j < dz; ++j) {
        for (double s : {-2.0, -1.0, 1.0, 2.0}) pts.push_back(mz + s * lz.col(j));
      }
      Eigen::MatrixXd phi(pts.size(), dz + 1), y(pts.size(), dx);
      for (size_t k = 0; k < pts.size(); ++k) {
        phi(k, 0) = 1.0;
        phi.row(k).tail(dz) = (pts[k] - mz).transpose();
        y.row(k) = CorrectedMean(r, c, pts[k], pitch_col, roll_col, corrected, share).transpose();
      }
      Eigen::MatrixXd w = phi.colPivHouseholderQr().solve(y);  // (dz+1) x dx
      mean_x = w.row(0).transpose();
      b = w.bottomRows(dz).transpose();
    }
    Eigen::VectorXd mean(dx + dz);
    Eigen::MatrixXd cov(dx + dz, dx + dz);
    mean << mean_x, mz;
    cov.topLeftCorner(dx, dx) = sigma + b * sz * b.transpose();
    if (dz > 0) {
      cov.topRightCorner(dx, dz) = b * sz;
      cov.bottomLeftCorner(dz, dx) = sz * b.transpose();
      cov.bottomRightCorner(dz, dz) = sz;
    }
    cov = 0.5 * (cov + cov.transpose());
    auto g = Gaussian::Create(mean, cov);
    if (!g) {
      cov.diagonal().array() += 1e-9 * (1.0 + cov.diagonal().array().abs());
      g = Gaussian::Create(mean, cov);
    }
    if (!g) continue;
    Mixture mix(dx + dz);
    mix.Add(1.0, *g);
    m.mixtures[c] = mix;
  }
  return m;
}

}  // namespace

MotionModel BuildSimModel(const Sim2RealResult& result, const SampleSet& sim) {
  return Build(result, sim, false);
}

MotionModel BuildCorrectedModel(const Sim2RealResult& result, const SampleSet& sim) {
  return Build(result, sim, true);
}

}  // namespace dgmm::sim2real
