#include "predict/predict.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "util/error.h"

namespace dgmm::predict {
namespace {

// Index of each wanted pose dimension in the model (dx, dy, dyaw[, dz, droll, dpitch]).
std::vector<int> PoseIndices(const MotionModel& model, const PredictOptions& options, bool* spatial) {
  std::vector<std::string> names = options.pose_dims;
  auto has = [&](const std::string& n) {
    for (const auto& p : model.pose_names) if (p == n) return true;
    return false;
  };
  if (names.empty()) {
    names = {"dx", "dy", "dyaw"};
    if (has("dz") && has("droll") && has("dpitch")) names = {"dx", "dy", "dyaw", "dz", "droll", "dpitch"};
  }
  if (names.size() != 3 && names.size() != 6) {
    throw MakeInputError("predict", "pose dims", "expected 3 names (dx, dy, dyaw) or 6 (dx, dy, dyaw, dz, droll, dpitch)");
  }
  std::vector<int> index;
  for (const auto& n : names) {
    int found = -1;
    for (int i = 0; i < model.pose_dim; ++i) {
      if (model.pose_names[i] == n) found = i;
    }
    if (found < 0) {
      throw MakeInputError("model", "pose", "has no pose dimension \"" + n + "\" (name the planar ones with --pose-dims)");
    }
    index.push_back(found);
  }
  *spatial = names.size() == 6;
  return index;
}

Eigen::Matrix3d Zyx(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Mean and covariance of the poses, yaw unwrapped about its circular mean.
void Summarise(StepPrediction* s) {
  Eigen::MatrixXd& p = s->poses;
  const double c = p.col(3).array().cos().mean(), sn = p.col(3).array().sin().mean();
  const double centre = std::atan2(sn, c);
  for (int i = 0; i < p.rows(); ++i) p(i, 3) = centre + std::remainder(p(i, 3) - centre, 2 * M_PI);
  s->mean = p.colwise().mean().transpose();
  const Eigen::MatrixXd d = p.rowwise() - s->mean.transpose();
  s->covariance = d.transpose() * d / std::max<Eigen::Index>(1, p.rows() - 1);
}

}  // namespace

bool PredictOptions::IsValid(std::string* error) const {
  if (trajectories < 1 || trajectories > 10000000) {
    if (error) *error = "trajectories: expected 1 to 10^7";
    return false;
  }
  return persistence.empty() || persistence.IsValid(error);
}

namespace {

// Standard normal noise of every trajectory for one step after another (pose_dim x n), each
// dimension's correlated with the previous steps' by a StepPersistence.
class PersistentNoise {
 public:
  PersistentNoise(const StepPersistence& p, int n, bool from_rest) : p_(p), n_(n), from_rest_(from_rest) {}
  Eigen::MatrixXd Next(std::mt19937_64& rng) {
    std::normal_distribution<double> normal;
    auto draw = [&] { return Eigen::MatrixXd(Eigen::MatrixXd::NullaryExpr(p_.shared.size(), n_, [&] { return normal(rng); })); };
    const Eigen::ArrayXd phi = p_.decay.array(), a = p_.shared.array();
    const bool first = u_.size() == 0;
    if (first) {
      u_ = draw();
    } else {
      u_ = (u_.array().colwise() * phi + draw().array().colwise() * (1 - phi.square()).sqrt()).matrix();
    }
    Eigen::MatrixXd eps = (u_.array().colwise() * a.sqrt() + draw().array().colwise() * (1 - a).sqrt()).matrix();
    if (first && from_rest_ && p_.first_scale.size() > 0) eps = p_.first_scale.asDiagonal() * eps;
    return eps;
  }

 private:
  const StepPersistence& p_;
  int n_;
  bool from_rest_;
  Eigen::MatrixXd u_;  // the persistent part u_t
};

// n pose changes (pose_dim x n) of step `k`, in raw units: from the step's terrain (or none), or
// with options.ground from the terrain under each trajectory's pose before the step; with `noise`
// (persistence) each drawn through that step's correlated noise.
Eigen::MatrixXd DrawStep(const MotionModel& model, const Step& step, const PredictOptions& options,
                         const Eigen::MatrixXd& poses, PersistentNoise* noise, std::mt19937_64& rng) {
  const int n = static_cast<int>(poses.rows());
  const Eigen::MatrixXd eps = noise ? noise->Next(rng) : Eigen::MatrixXd();
  auto draw = [&](const Mixture& p, int first, int count) {
    return noise ? p.SampleWithNoise(eps.middleCols(first, count), rng) : p.Sample(count, rng);
  };
  if (!options.ground || (step.terrain.size() > 0 && step.terrain.allFinite())) {
    return draw(model.RawPoseDistribution(step.command, step.terrain), 0, n);
  }
  Eigen::MatrixXd dx(model.pose_dim, n);
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd z = options.ground(poses.row(i).transpose());
    if (step.terrain.size() > 0) z = step.terrain.array().isNaN().select(z, step.terrain);
    if (!z.allFinite()) throw MakeInputError("predict", "terrain", "a dimension is given neither by the step nor by the ground");
    dx.col(i) = draw(model.RawPoseDistribution(step.command, z), i, 1);
  }
  return dx;
}

}  // namespace

Prediction Predict(const MotionModel& model, const Eigen::Vector3d& start, const std::vector<Step>& steps,
                   const PredictOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("predict", "", error);
  if (options.ground && model.terrain_dim == 0) {
    throw MakeInputError("predict", "ground", "the model was fitted without terrain: it cannot be conditioned on the ground");
  }
  Prediction out;
  const std::vector<int> idx = PoseIndices(model, options, &out.spatial);
  const int n = options.trajectories;
  std::vector<Eigen::Matrix3d> rotation(n, Zyx(start.z(), 0, 0));
  Eigen::MatrixXd position(n, 3);
  position.col(0).setConstant(start.x());
  position.col(1).setConstant(start.y());
  position.col(2).setZero();
  Eigen::MatrixXd before(n, 4);  // every trajectory's pose before the step: x, y, z, yaw
  before.leftCols(3) = position;
  before.col(3).setConstant(start.z());
  if (!options.persistence.empty() && options.persistence.shared.size() != model.pose_dim) {
    throw MakeInputError("predict", "persistence", "expected one value per pose dimension of the model (" +
                                                       std::to_string(model.pose_dim) + ")");
  }
  std::mt19937_64 rng(options.seed);
  std::optional<PersistentNoise> noise;
  if (!options.persistence.empty()) noise.emplace(options.persistence, n, options.from_rest);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const Step& step = steps[k];
    if (!model.HasCommand(step.command)) {
      throw MakeInputError("model", "command", "step " + std::to_string(k + 1) + ": the model has no such command");
    }
    if (step.terrain.size() > 0 && step.terrain.size() != model.terrain_dim) {
      throw MakeInputError("predict", "terrain", "step " + std::to_string(k + 1) + ": expected " +
                                                     std::to_string(model.terrain_dim) + " terrain values");
    }
    if (!options.ground && !step.terrain.allFinite()) {
      throw MakeInputError("predict", "terrain", "step " + std::to_string(k + 1) + ": expected finite terrain values");
    }
    const Eigen::MatrixXd dx = DrawStep(model, step, options, before, noise ? &*noise : nullptr, rng);  // pose_dim x n
    StepPrediction s;
    s.poses.resize(n, 4);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d t(dx(idx[0], i), dx(idx[1], i), out.spatial ? dx(idx[3], i) : 0.0);
      const Eigen::Matrix3d r = out.spatial ? Zyx(dx(idx[2], i), dx(idx[5], i), dx(idx[4], i)) : Zyx(dx(idx[2], i), 0, 0);
      position.row(i) += (rotation[i] * t).transpose();
      rotation[i] = rotation[i] * r;
      s.poses.row(i) << position(i, 0), position(i, 1), position(i, 2), std::atan2(rotation[i](1, 0), rotation[i](0, 0));
    }
    before = s.poses;
    Summarise(&s);
    out.steps.push_back(std::move(s));
  }
  return out;
}

}  // namespace dgmm::predict
