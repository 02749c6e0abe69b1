#pragma once
// A small analytic stand-in for the simulator, for tests and for shipping synthetic pairs when
// MuJoCo is unavailable: x = f(c, g) + effects(c, g, first) + noise, with the paper's protocol
// (26 commands {-0.5, 0, 0.5}^3 minus the no-op; placements cycling 0, 90 (facing downhill) and
// -90 deg on an inclined plane; 5 executions per placement). Clearly labelled "synthetic" in the
// set's metadata. The effects use the same parametric forms and units as the effect library
// (sim2real/effects.h), so a planted value is directly the parameter the analysis should recover.
#include <Eigen/Dense>
#include <cstdint>
#include <string>

#include "core/sample_set.h"

namespace dgmm::sim2real {

struct SyntheticWorld {
  double slope_deg = 18.0;
  double placement_jitter_rad = 0.02;  // sd of pitch/roll around the nominal placement
  // Noise sd of <dx, dy, dz, droll, dpitch, dyaw> (m, rad) before noise_scale.
  Eigen::VectorXd noise_sd = (Eigen::VectorXd(6) << 0.012, 0.012, 0.004, 0.01, 0.01, 0.02).finished();
  // Planted effects (0: absent), in the units of the effect library.
  double slip_creep = 0;            // m per execution per unit horizontal gravity
  double stride_loss = 0;           // fraction
  double slope_traction = 0;        // fraction per unit downhill alignment
  double payload_drift_y = 0;                              // m per execution
  double payload_yaw_per_gx = 0, payload_yaw_per_gy = 0;  // rad per execution per unit gravity
  double asymmetry_yaw_per_execution = 0, asymmetry_yaw_per_metre = 0;  // per metre forward
  double asymmetry_yaw_per_gx = 0;  // the weak leg matters more when loaded (rad per unit g_x)
  double latency_first_loss = 0;    // fraction lost at the first execution of a placement
  double sink = 0, attitude_damping = 0;
  Eigen::VectorXd bias;             // empty or 6 entries
  double noise_scale = 1.0;
};

// "paper": 390 samples (26 commands x 3 placements x 5); "paper-830": placements cycle on until
// 830 samples. Same seed, same set. Throws InputError for an unknown protocol.
SampleSet GenerateSynthetic(const SyntheticWorld& world, const std::string& protocol,
                            std::uint64_t seed);

}  // namespace dgmm::sim2real
