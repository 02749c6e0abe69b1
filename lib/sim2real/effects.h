#pragma once
// The library of candidate physical effects. Each is a small parametric correction of the
// sim model's predictive distribution p_sim(x | c, z, prev) = N(u, Sigma):
//   mean u -> u + D_e(u, g, first) theta_e   (D_e: dx x p_e, linear in the parameters),
//   covariance Sigma -> tau^2 Sigma          (the noise effect, one parameter log tau),
// computed from the sim prediction u, the unit gravity g in the body frame (from pitch, roll)
// and whether the execution is the first after a change of command.
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "sim2real/samples.h"

namespace dgmm::sim2real {

enum class EffectId {
  kSlopeSlip,         // downhill creep along gravity's horizontal component in the body frame
  kStrideLoss,        // forward, lateral displacement and turn each scaled down
  kSlopeTraction,     // scaling that differs uphill and downhill
  kPayloadOffset,     // off-centre mass: drift/yaw linear in gravity, load-shortened strides
  kActuatorAsymmetry, // weak side: drift/yaw per direction of each commanded component
  kLatency,           // motion lost at the first execution after a command change (backlash)
  kCompliance,        // sinking (dz) and damped attitude changes on soft ground
  kBias,              // constant offset of every pose dimension (tracker, calibration)
  kNoise,             // real spread larger than simulated: Sigma * tau^2
  kExternal,          // a design supplied from outside the library (simulated knob signatures)
};

struct EffectParameter {
  std::string name;  // e.g. "creep"
  std::string unit;  // e.g. "m per execution per unit horizontal gravity"
};

struct EffectSpec {
  EffectId id;
  std::string key;    // stable identifier used in report.json, e.g. "slope_slip"
  std::string title;  // e.g. "Slope-induced slip"
  std::string physics;  // one line: what the simulation left out
  std::vector<EffectParameter> parameters;
  bool needs_terrain = false;
  bool needs_sequence = false;
  bool is_noise = false;
  int num_params() const { return static_cast<int>(parameters.size()); }
};

// The effects usable with this data (terrain/sequence/pose layout permitting), library order.
std::vector<EffectSpec> EffectLibrary(const PoseLayout& layout, int pose_dim, bool has_terrain,
                                      bool has_sequence);

// Mean-shift design D_e (dx x p_e) of a mean effect for one sample: sim mean u, gravity g (3),
// first-execution flag. Zero matrix for the noise effect.
Eigen::MatrixXd EffectDesign(const EffectSpec& effect, const PoseLayout& layout,
                             const Eigen::Ref<const Eigen::VectorXd>& sim_mean,
                             const Eigen::Ref<const Eigen::Vector3d>& gravity, bool first_execution);

// One plain-language sentence for fitted parameters theta (p_e), with `slope_sin` the typical
// horizontal gravity |g_h| of the real data (sin of the slope) to express terrain effects.
std::string DescribeEffect(const EffectSpec& effect, const Eigen::VectorXd& theta,
                           double slope_sin);

}  // namespace dgmm::sim2real
