#include "predict/predict.h"

#include <Eigen/Cholesky>
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

// (p - m)^T C^-1 (p - m) in (x, y) of each row of `points` under the step's mean and covariance.
Eigen::VectorXd Distance2(const StepPrediction& s, const Eigen::MatrixX2d& points) {
  Eigen::Matrix2d c = s.covariance.topLeftCorner<2, 2>();
  c.diagonal().array() += 1e-12 * (c.trace() > 0 ? c.trace() : 1.0);  // as the fan's: all equal still factors
  const Eigen::LLT<Eigen::Matrix2d> llt(c);
  const Eigen::MatrixX2d centred = points.rowwise() - s.mean.head<2>().transpose();
  return llt.matrixL().solve(centred.transpose()).colwise().squaredNorm().transpose();
}

// The q-quantile of v (nearest rank below).
double Quantile(Eigen::VectorXd v, double q) {
  const auto at = static_cast<Eigen::Index>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.data(), v.data() + at, v.data() + v.size());
  return v[at];
}

// Mean and covariance of the poses, yaw unwrapped about its circular mean; the planar regions of
// step `k`.
void Summarise(const PredictOptions& options, int k, StepPrediction* s) {
  Eigen::MatrixXd& p = s->poses;
  const double c = p.col(3).array().cos().mean(), sn = p.col(3).array().sin().mean();
  const double centre = std::atan2(sn, c);
  for (int i = 0; i < p.rows(); ++i) p(i, 3) = centre + std::remainder(p(i, 3) - centre, 2 * M_PI);
  s->mean = p.colwise().mean().transpose();
  const Eigen::MatrixXd d = p.rowwise() - s->mean.transpose();
  s->covariance = d.transpose() * d / std::max<Eigen::Index>(1, p.rows() - 1);
  const Eigen::VectorXd d2 = Distance2(*s, p.leftCols(2));
  const RegionCalibration& cal = options.calibration;
  s->region_levels = cal.empty() ? options.region_levels : cal.levels;
  s->region_r2.clear();
  for (std::size_t l = 0; l < s->region_levels.size(); ++l) {
    const double factor = cal.empty() ? 1.0 : cal.Factor(k, static_cast<int>(l));
    s->region_r2.push_back(factor * Quantile(d2, s->region_levels[l]));
  }
}

// Advances a pose (rotation, position) by one pose change dx (the model's dimensions): the
// translation in the robot's frame at the start of the command, then the rotation.
void Advance(const Eigen::Ref<const Eigen::VectorXd>& dx, const std::vector<int>& idx, bool spatial,
             Eigen::Matrix3d* rotation, Eigen::Vector3d* position) {
  const Eigen::Vector3d t(dx[idx[0]], dx[idx[1]], spatial ? dx[idx[3]] : 0.0);
  const Eigen::Matrix3d r = spatial ? Zyx(dx[idx[2]], dx[idx[5]], dx[idx[4]]) : Zyx(dx[idx[2]], 0, 0);
  *position += *rotation * t;
  *rotation = *rotation * r;
}

Eigen::RowVector4d PoseRow(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& position) {
  return {position.x(), position.y(), position.z(), std::atan2(rotation(1, 0), rotation(0, 0))};
}

}  // namespace

bool PredictOptions::IsValid(std::string* error) const {
  if (trajectories < 1 || trajectories > 10000000) {
    if (error) *error = "trajectories: expected 1 to 10^7";
    return false;
  }
  for (double level : calibration.empty() ? region_levels : calibration.levels) {
    if (!(level > 0 && level < 1)) {
      if (error) *error = "region levels: expected shares in (0, 1)";
      return false;
    }
  }
  if (!calibration.empty() && (calibration.factor.cols() != static_cast<Eigen::Index>(calibration.levels.size()) ||
                               !(calibration.factor.array() > 0).all() || !calibration.factor.allFinite())) {
    if (error) *error = "calibration: expected a positive factor per horizon and level";
    return false;
  }
  return persistence.empty() || persistence.IsValid(error);
}

double RegionCalibration::Factor(int step, int level) const {
  return factor(std::clamp<Eigen::Index>(step, 0, factor.rows() - 1), level);
}

double StepPrediction::RegionDistance2(const Eigen::Vector2d& p) const {
  return Distance2(*this, p.transpose())[0];
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
  std::vector<Eigen::Vector3d> position(n, Eigen::Vector3d(start.x(), start.y(), 0.0));
  Eigen::MatrixXd before(n, 4);  // every trajectory's pose before the step: x, y, z, yaw
  before.rowwise() = Eigen::RowVector4d(start.x(), start.y(), 0.0, start.z());
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
      Advance(dx.col(i), idx, out.spatial, &rotation[i], &position[i]);
      s.poses.row(i) = PoseRow(rotation[i], position[i]);
    }
    before = s.poses;
    Summarise(options, static_cast<int>(k), &s);
    out.steps.push_back(std::move(s));
  }
  return out;
}

Eigen::MatrixXd ComposePath(const MotionModel& model, const Eigen::Vector3d& start, const Eigen::MatrixXd& x,
                            const PredictOptions& options) {
  if (x.cols() != model.pose_dim) throw MakeInputError("predict", "path", "expected the model's pose dimensions");
  bool spatial = false;
  const std::vector<int> idx = PoseIndices(model, options, &spatial);
  Eigen::Matrix3d rotation = Zyx(start.z(), 0, 0);
  Eigen::Vector3d position(start.x(), start.y(), 0.0);
  Eigen::MatrixXd poses(x.rows(), 4);
  for (Eigen::Index k = 0; k < x.rows(); ++k) {
    Advance(x.row(k).transpose(), idx, spatial, &rotation, &position);
    poses.row(k) = PoseRow(rotation, position);
  }
  return poses;
}

}  // namespace dgmm::predict
