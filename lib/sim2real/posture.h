#pragma once
// The torso's posture as evidence beside the motion (docs/sim2real.md, "The torso's posture"):
// every model here is of x given z, so z itself, the IMU's pitch and roll at the start of each
// execution, is never compared; yet a payload or a weak leg tilts how the robot stands and walks,
// and a tracker offset, heading drift or friction does not. On level ground z does not depend on
// the heading, so sets of other placements compare by their mean z per command:
//   d(a, b) = mean_c (mean z_a|c - mean z_b|c)          (commands both sets have)
// observed d(real, sim) with a standard error from resampling both sets' placements (seeded), the
// correction's own shift d(corrected, nominal) from its recording at the sim set's places (its
// error from resampling those places jointly: a legged robot's roll can switch between gaits from
// one placement to the next) plus a named IMU offset b (recorded z = true z + b), and what is left
//   l = d(real, sim) - d(corrected, nominal) - b.
// A component of l at >= z standard errors is a posture the named physics does not give. The same
// for the first execution of each placement (the robot standing after it was placed) tells the
// two apart: an IMU mounted off level moves both alike, a payload or a weak leg the walking
// posture far more than the standing one. On a slope tilted by gravity z lies on a closed curve
// around the posture (radius the slope), and where on it depends on the heading, which a turn
// changes between executions: there only the radial part of z compares (SlopeGeometry),
//   rho~ = |z - c| - R(theta),   mean rho~_a - mean rho~_b = u . d   per (command, direction) cell,
// with c the sim set's circle centre, R its radius per direction theta (harmonics up to the
// second), u the cell's unit direction, d the posture shift (least squares over the cells both sets
// have). On a height field z depends on where the robot stands: the check does not run there.
// Where the analysis only locates (no simulator), the real posture is compared with the sim set's
// alone (ComparePosture): a posture that moved is a located mismatch.
#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/inputs.h"
#include "sim2real/knob_simulator.h"
#include "sim2real/simulation_cache.h"

namespace dgmm::sim2real {

// What the check needs to know of the ground: a plane (no height field: z follows the heading
// alone) and a level one (else a slope: SlopeGeometry). From the simulator where there is one
// (GroundOf); else from the sim set's config (the app); unknown without either.
struct PostureGround {
  bool known = false;
  bool plane = false;
  bool level = false;
};

struct PostureOptions {
  bool enabled = true;  // `dgmm sim2real --no-posture` turns it off
  PostureGround ground;  // used only where the analysis has no simulator (it only locates)
  // Standard errors a component of the posture left must reach (two components, pitch and roll;
  // the nulls of the planar and sprawled quadrupeds reached at most 2.8, docs/sim2real.md).
  double z = 4.0;
  int resamples = 200;  // placement resamples of both sets for the standard errors
  std::uint64_t seed = 1;
  // When the named IMU offset is what leaves the posture out (the rest of the correction gives the
  // real posture without it), the analysis runs again from the candidates without an IMU offset
  // among them (ContradictedImu); false: the offset stays named, with the doubt.
  bool refit_without_imu = true;
  bool IsValid(std::string* error) const;
};

// Where z lies on a slope tilted by gravity, fitted to a reference set: the circle's centre c
// (algebraic least squares) and its radius per direction, R(theta) = h(theta) . radius with
// h = (1, cos, sin, cos 2theta, sin 2theta) (minimum-norm least squares: three headings suffice).
struct SlopeGeometry {
  bool valid = false;
  std::string why;  // why not valid
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 5, 1> radius = Eigen::Matrix<double, 5, 1>::Zero();
  int directions = 12;  // cells per command by the direction of z - c (bins centred on multiples of 30 deg)
  // Rows whose |rho~| exceeds this are left out: an execution that ended with the robot tipped
  // or wedged (on the hexapod 0.6 rad off the circle) is no posture. 6 robust SDs (1.4826 MAD)
  // of the reference's rho~.
  double outlier_rad = 0;
};
// Fitted to every row of `reference`; not valid when z does not trace a circle clearly (its radius
// under 4 times the robust SD of the radial residuals).
SlopeGeometry FitSlopeGeometry(const SampleSet& reference, int pitch_col, int roll_col);

// z's radial part on the slope's circle, rho~ = |z - c| - R(theta) (z: pitch, roll in rad).
double RadialResidual(const SlopeGeometry& g, const Eigen::Vector2d& z);

// Per command mean z (pitch, roll columns) of `a` minus that of `b`, averaged over the commands
// both have (matched by label), on the rows `rows_a` and `rows_b`; NaN without a shared command.
// With `slope`, the posture shift d from the radial parts per (command, direction) cell (above);
// NaN when the cells both have do not span two directions.
Eigen::Vector2d PostureDifference(const SampleSet& a, const std::vector<int>& rows_a, const SampleSet& b,
                                  const std::vector<int>& rows_b, int pitch_col, int roll_col,
                                  const SlopeGeometry* slope = nullptr);

// d(a, b) on every row (`first_only`: the first execution of each placement) and its standard
// error from `resamples` draws of each set's placements with replacement.
struct PostureShift {
  Eigen::Vector2d shift = Eigen::Vector2d::Constant(NAN), se = Eigen::Vector2d::Constant(NAN);
};
PostureShift MeasurePostureShift(const SampleSet& a, const SampleSet& b, int pitch_col, int roll_col, bool first_only,
                                 int resamples, std::uint64_t seed, const SlopeGeometry* slope = nullptr);

// d(a, b) of two recordings at the same places (`a` a knob's, `b` the nominal's), its standard
// error from resampling the placements both have, jointly (a paired difference).
PostureShift MeasurePairedPostureShift(const SampleSet& a, const SampleSet& b, int pitch_col, int roll_col,
                                       bool first_only, int resamples, std::uint64_t seed,
                                       const SlopeGeometry* slope = nullptr);

struct PostureCheck {
  bool ran = false;
  std::string why;             // why it did not run
  PostureShift walking;        // real minus sim, every execution (rad)
  PostureShift standing;       // real minus sim, first executions of a placement (rad)
  Eigen::Vector2d predicted = Eigen::Vector2d::Zero();           // the correction's own shift (rad)
  Eigen::Vector2d predicted_se = Eigen::Vector2d::Zero();        // its paired standard error
  Eigen::Vector2d predicted_standing = Eigen::Vector2d::Zero();
  Eigen::Vector2d left = Eigen::Vector2d::Zero();                // walking minus predicted
  double z_left = 0;           // max |left| / sqrt(se^2 + predicted_se^2) over pitch and roll
  double z_moved = 0;          // max |walking| / se: did the posture move at all
  bool left_out = false;       // z_left >= options.z: a posture the named physics does not give
  Eigen::Vector2d imu = Eigen::Vector2d::Zero();  // the named IMU offset in `predicted`
  double z_left_without_imu = 0;  // the same without it (a named IMU offset the posture contradicts)
  bool recorded = false;       // the correction was recorded (false: it holds no simulator knob)
  std::string correction;      // what was checked, in words ("nothing named", "the named correction")
  bool on_slope = false;       // compared by the radial part of z on the slope's circle (SlopeGeometry)
  bool compared_only = false;  // real against sim alone (ComparePosture): no correction checked
};

PostureGround GroundOf(const KnobSimulator& simulator);

// The real set's posture against the sim set's alone, walking and standing (`predicted` zero): the
// first half of CheckPosture, and all of the check where the analysis only locates. `left_out`
// when it moved by options.z standard errors.
PostureCheck ComparePosture(const AnalysisInputs& in, const PostureGround& ground, const PostureOptions& options);

// The check for a correction of simulator knobs `values` (may be empty) and an IMU offset `imu`
// (rad, pitch and roll; zero when none is named). The ground from the simulator (level_ground,
// plane_ground: on a slope the sets compare by SlopeGeometry, fitted to the sim set); `nominal` the
// nominal re-recording at the sim set's places the correction's recording pairs with.
PostureCheck CheckPosture(const KnobSimulator& simulator, const AnalysisInputs& in, const SampleSet& nominal,
                          const Recording& recording, const RecordingOptions& recording_options,
                          const std::vector<KnobValue>& values, const Eigen::Vector2d& imu,
                          const std::string& correction, const PostureOptions& options);

// CheckPosture's second half: the correction set against `compared` (ComparePosture's real set
// against the sim set, kept as it is), so that several corrections checked against one comparison
// share its resampling (the payload search's columns).
PostureCheck CheckCorrectionPosture(const PostureCheck& compared, const KnobSimulator& simulator,
                                    const AnalysisInputs& in, const SampleSet& nominal, const Recording& recording,
                                    const RecordingOptions& recording_options, const std::vector<KnobValue>& values,
                                    const Eigen::Vector2d& imu, const std::string& correction,
                                    const PostureOptions& options);

// A named IMU offset the posture contradicted: the first fit's names and its posture check (the
// offset, z left with and without it); the analysis's stages from the candidates then ran again
// without an IMU offset (PostureOptions::refit_without_imu).
struct ContradictedImu {
  bool refitted = false;
  std::vector<std::string> named;  // what the first fit named (knob names, the IMU offset's among them)
  PostureCheck check;              // the first fit's posture check
};

// Does `check` contradict its named IMU offset: the posture left out with it, not without it?
bool ContradictsNamedImu(const PostureCheck& check, double z);

// " A first fit named a, b and an IMU offset of (p, r) mrad, which the torso's posture contradicts
// (z SE left with it, z without): the stages from the candidates ran again without an IMU offset."
// Empty when nothing was refitted.
std::string ContradictedImuSentence(const ContradictedImu& c);

// The check in the verdict: a posture left out is a doubt (explained becomes partly_explained,
// clean becomes unexplained) and a sentence; after ComparePosture alone a posture that moved is a
// located mismatch (clean becomes located) and a sentence.
struct Verdict;
void AddPostureCheck(const PostureCheck& check, double z, Verdict* v);

}  // namespace dgmm::sim2real
