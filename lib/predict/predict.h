#pragma once
// Where a command sequence takes the robot: the pose distribution after each command, by Monte
// Carlo composition of pose changes drawn from the model's p(x | c, z) in the robot's frame
// (SE(2) for a planar pose change (dx, dy, dyaw), SE(3) for (dx, dy, dz, droll, dpitch, dyaw),
// ZYX Euler angles of the change relative to the start of the command).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/motion_model.h"
#include "predict/step_persistence.h"

namespace dgmm::predict {

// How much the planar regions of a prediction are widened so that they hold their shares of
// outcomes on episodes the model did not learn from (region_calibration.h); empty: not widened.
struct RegionCalibration {
  std::vector<double> levels;  // the regions' shares, e.g. 0.5 and 0.9
  // horizons x levels: the factor on r^2 after k + 1 commands (1: the trajectories' own quantile);
  // steps beyond the last horizon take its factor.
  Eigen::MatrixXd factor;
  Eigen::VectorXi episodes;  // per horizon: the calibration episodes that reached it
  bool empty() const { return factor.size() == 0; }
  double Factor(int step, int level) const;  // step counts from 0
};

struct PredictOptions {
  int trajectories = 1000;
  std::uint64_t seed = 1;
  // Names of the pose-change dimensions, in the model's pose_names; empty: "dx,dy,dyaw" plus
  // "dz,droll,dpitch" when the model has them all (SE(3)).
  std::vector<std::string> pose_dims;
  // The terrain under a pose (x, y, z, yaw) for steps without a terrain of their own: each
  // trajectory is conditioned on the ground where it stands before the step (e.g. a plane's
  // pitch and roll at its heading, GroundTerrain of ground_terrain.h). Empty: steps without a terrain marginalise it.
  std::function<Eigen::VectorXd(const Eigen::Vector4d& pose)> ground;
  // How deviations carry from one command to the next (step_persistence.h, one value per pose
  // dimension of the model); empty: every step drawn independently given its command and terrain.
  StepPersistence persistence;
  // The robot stands before the first command (persistence.first_scale applies); false: it is
  // already walking.
  bool from_rest = true;
  // Shares of the planar regions reported per step (StepPrediction::region_r2); with a calibration
  // its levels are used and its factors applied.
  std::vector<double> region_levels{0.5, 0.9};
  RegionCalibration calibration;
  bool IsValid(std::string* error) const;
};

// One step of the sequence: the command's id in the model and the terrain to condition on (empty:
// p(x | c), the terrain marginalised). With PredictOptions::ground, NaN entries (or an empty
// terrain) are read off the ground under each trajectory and the others (continuous command
// values, say) are kept.
struct Step {
  int command = -1;
  Eigen::VectorXd terrain;
};

struct StepPrediction {
  // World pose of every trajectory after the step: x, y, z (m), yaw (rad, unwrapped about the
  // mean); z is 0 for planar models.
  Eigen::MatrixXd poses;      // trajectories x 4
  Eigen::Vector4d mean = Eigen::Vector4d::Zero();
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  // Planar regions {p : (p - m)^T C^-1 (p - m) <= r2} in (x, y), m and C the trajectories' mean and
  // covariance there: per level, r2 = the level-quantile of the trajectories' own squared
  // Mahalanobis distances, times the calibration's factor.
  std::vector<double> region_levels;
  std::vector<double> region_r2;
  // (p - m)^T C^-1 (p - m) of a point p = (x, y) (RegionDistance2 < r2: inside).
  double RegionDistance2(const Eigen::Vector2d& p) const;
};

struct Prediction {
  bool spatial = false;  // SE(3) composition
  std::vector<StepPrediction> steps;
};

// Start pose: x, y (m), yaw (rad) in the world; z, roll and pitch start at zero. A model fitted
// on standardised data is conditioned and sampled in its own units and reported in raw ones. Throws
// InputError naming the part (options, a pose dimension the model lacks, a command it does not
// know, a terrain of the wrong size).
Prediction Predict(const MotionModel& model, const Eigen::Vector3d& start, const std::vector<Step>& steps,
                   const PredictOptions& options);

// The path of recorded pose changes (rows of x, raw units, the model's pose dimensions) composed
// from `start` as Predict composes its draws: poses x, y, z, yaw after each row (rows x 4).
Eigen::MatrixXd ComposePath(const MotionModel& model, const Eigen::Vector3d& start, const Eigen::MatrixXd& x,
                            const PredictOptions& options);

}  // namespace dgmm::predict
