#pragma once
// The walk's own chance (docs/sim2real.md, "A chaotic walk"). Stage 3 (candidates.h) records the
// nominal once more with the payload heavier by a small share of the robot's mass (at its place, the
// torso centre without one: a change no measurement of the real robot could see), paired with the
// nominal recording. Where the simulated walk is chaotic, that change alone moves every execution,
//   ratio_j = RMS_i (x'_ij - x_ij) / sd_j   (sd_j the nominal's spread about each command's fit;
//                                            0: the executions pair, sqrt 2: as unrelated as two draws),
// and the paired shift fitted from it (signatures.h) is what chance makes of any probe's signature:
//   chance share_k = |S_chance| / |S_k|,   |S|^2 = mean over the real samples of sum_j (S_j / sd_j)^2.
// Near 1, a candidate's signature is the walk's chance as much as its physics.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/knob_simulator.h"
#include "sim2real/samples.h"
#include "sim2real/signatures.h"

namespace dgmm::sim2real {

struct WalkChanceOptions {
  double share = 3e-4;  // of the robot's total mass (1 g on a 3.2 kg robot); 0: not measured
  bool IsValid(std::string* error) const;
};

struct WalkChance {
  bool measured = false;
  std::string why_not;            // when not measured, in words
  double added_kg = 0;            // the payload's change recorded
  std::optional<PairedShift> shift;  // the replica's paired shift from the nominal
  Eigen::VectorXd spread;         // the nominal's sd per pose axis (floored relative to its largest)
  double size = 0;                // |S_chance| over the real samples, in units of `spread`
  Eigen::VectorXd paired_ratio;   // per pose axis
  int largest_axis = -1;
  double largest_ratio = 0;
};

// The knob values of the replica (the payload's mass knob at its nominal + share x total mass);
// empty when the simulator has no payload mass knob or the share is 0.
std::vector<KnobValue> ChanceRequest(const KnobSimulator& simulator, const WalkChanceOptions& options);

// The chance measured from the nominal recording and its replica (at ChanceRequest's values), its
// size over the real samples; not measured, with the reason, when too few executions pair up.
WalkChance MeasureWalkChance(const SampleSet& nominal, const SampleSet& replica, const SampleSet& table,
                             const Samples& real, double added_kg, double slope_ridge);

// |S| of the shifts `of` (the largest of them) over the real samples, per axis in units of `sd`.
double SignatureSize(const std::vector<PairedShift>& shifts, const std::vector<int>& of, const Samples& real,
                     const Eigen::VectorXd& sd);

// The chance share of a candidate with the shifts `of`; NaN when the chance was not measured or
// the candidate has no shifts.
double ChanceShare(const WalkChance& chance, const std::vector<PairedShift>& shifts, const std::vector<int>& of,
                   const Samples& real);

// The chance share of a fitted effect, its mean shift D theta (D: raw design, row i dx + j for
// real sample i and axis j) against the chance its probes' signatures carry, one |S_chance| each:
//   |S_chance| |theta|_2 / |D theta|   (NaN when the chance was not measured).
double FittedChanceShare(const WalkChance& chance, const Eigen::MatrixXd& design, const Eigen::VectorXd& theta,
                         const Samples& real);

}  // namespace dgmm::sim2real
