#pragma once
// Designs of the knob analysis's candidates that are not the data-level library's effects
// (knob_analysis.h): a simulated knob probe (its paired shift), the payload (three probes), the
// IMU pitch/roll offset (through the sim model's slopes), heading drift (yaw) and the tracker bias
// (every pose axis but yaw).
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "sim2real/effect_fit.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/samples.h"
#include "sim2real/signatures.h"

namespace dgmm::sim2real {

// One candidate of the knob analysis: which design it has and which paired shifts it uses.
struct ExternalCandidate {
  enum Kind { kShift, kPayload, kImuBias, kHeading, kTrackerBias } kind = kShift;
  // Indices into the PairedShift list. Payload: (centre, x, y) probes, or after refinement
  // (refined, centre, x, y): column 0 is then the payload simulated at the refined mass and
  // position, columns 1-2 stay the probes' position directions (x - centre, y - centre).
  std::vector<int> shifts;
};

// Mean-shift design D (dx x p) of candidate e for command c, terrain z (terrain_dim), first-execution
// flag f: mean += D theta. `shifts` are the simulated probes' paired shifts, `model` the sim model.
Eigen::MatrixXd ExternalDesign(const ExternalCandidate& e, const std::vector<PairedShift>& shifts,
                               const LinearGaussianModel& model, const PoseLayout& layout, int dx, int c,
                               const Eigen::VectorXd& z, double f);

// A library entry (EffectId::kExternal) with `params` parameters in `unit`; its designs are filled
// in by the knob analysis from ExternalDesign.
EffectSpec ExternalSpec(const std::string& key, const std::string& title, int params, const std::string& unit);

}  // namespace dgmm::sim2real
