#pragma once
// A fake simulator for the sim2real analysis's logic (lib/sim2real/knob_simulator.h): a
// linear-Gaussian toy robot on a tilted plane whose knobs shift the pose change (dx, dy, dyaw)
// by known signatures, with common random numbers (a recording's placements, commands and noise
// depend on its seed only, never on the knob values). Its recordings take milliseconds, so tests
// run the whole analysis on planted "real" sets: a knob at a planted value, measurement effects,
// or physics no knob describes.
//
//   x = base(c, g) + sum_k s_k(v_k) S_k(c, g, first) + noise_scale * e,   e ~ N(0, diag(sd^2))
// with c = (long, lat, turn), g the unit gravity in the body frame from (pitch, roll), and
// s_k(v) the knob's size at value v (0 at the nominal; friction is mildly non-linear so that its
// refinement has work to do).
#include <Eigen/Dense>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/knob_simulator.h"

namespace dgmm::sim2real::test {

// Knob indices of the fake, in its knobs() order.
enum FakeKnob {
  kFriction = 0,  // family friction, nominal 1, range [0.3, 1.5]
  kLeftGain,      // actuator_gain, side left
  kRightGain,     // actuator_gain, side right
  kLeg0Gain, kLeg1Gain, kLeg2Gain, kLeg3Gain,  // actuator_gain per leg (0, 1 left; 2, 3 right)
  kLatency,       // latency (first executions only)
  kPayloadMass, kPayloadX, kPayloadY,
  kTrackerNoise,  // spread
  kTorsional,     // changes nothing (inert)
  kNumFakeKnobs
};

// The fake payload's effect is gain times its signature: its mass's own part (speed lost, weight)
// taken at mass^power (power 1: linear in the mass, as its probes' reading assumes), its offsets'
// part at the moments mass x and mass y.
struct FakePayload {
  double gain = 1, power = 1;
  // A forward offset either way bends the walk: dyaw += bend mass |x| long (a sideways offset's
  // signature, so the probes' linear reading of a payload behind the middle is sideways too).
  double bend = 0;
  // The forward offset acts by itself, as if the mass were always 2.5 kg (on the mammal-shaped
  // robot's trot the data fix the offset, not the moment M x).
  bool offset_alone = false;
  // Each payload mass walks its own way, as recordings of a chaotic walk do: the payload's whole
  // effect times 1 + chaos u, u in [-1, 1] drawn from the mass's value alone.
  double chaos = 0;
};

// What a recording adds beyond the knobs (the "real" robot's extras).
struct FakeExtras {
  Eigen::Vector3d tracker_bias = Eigen::Vector3d::Zero();  // added to (dx, dy, dyaw); yaw entry unused
  // Physics no knob describes: dy += geometry * long * (1 + 2 roll), dx -= geometry * |turn|.
  double geometry = 0;
  // On level ground (FakeSimulator::level): a tilt of z (pitch, roll; rad) no knob gives.
  Eigen::Vector2d posture = Eigen::Vector2d::Zero();
  // The motion as if the ground were tilted by this (pitch, roll; rad) while the torso stays as it
  // is: x given z reads like an IMU offset, z does not move.
  Eigen::Vector2d motion_tilt = Eigen::Vector2d::Zero();
  // An IMU offset: recorded z = true z + imu_offset.
  Eigen::Vector2d imu_offset = Eigen::Vector2d::Zero();
};

class FakeSimulator : public KnobSimulator {
 public:
  FakeSimulator();
  // A fake whose friction only slips below `threshold` (slip 2 (threshold - f) below it, none
  // above, as a Coulomb contact's), probed at `probes`.
  FakeSimulator(double friction_threshold, std::vector<double> friction_probes);
  const std::vector<Knob>& knobs() const override { return knobs_; }
  std::string Fingerprint() const override {
    return (friction_threshold_ > 0 ? "fake-simulator-v1-threshold-" + std::to_string(friction_threshold_)
                                    : "fake-simulator-v1") +
           (ground_sd > 0 ? "-ground-" + std::to_string(ground_sd) : "") + (honour_executions ? "-executions" : "") +
           (payload.power != 1 || payload.gain != 1 || payload.bend != 0
                ? "-payload-" + std::to_string(payload.gain) + "-" + std::to_string(payload.power) + "-" +
                      std::to_string(payload.bend)
                : "") +
           (payload.offset_alone ? "-offset-alone" : "") +
           (payload.chaos != 0 ? "-chaos-" + std::to_string(payload.chaos) : "") + (level ? "-level" : "") +
           (sloped_plane ? "-sloped-plane" : "") +
           (level_z_sd != 0.02 ? "-z-sd-" + std::to_string(level_z_sd) : "") +
           (tilt_steers != 0 ? "-tilt-steers-" + std::to_string(tilt_steers) : "") +
           (walk_chaos != 0 ? "-walk-chaos-" + std::to_string(walk_chaos) : "") +
           (nominal_luck != 0 ? "-nominal-luck-" + std::to_string(nominal_luck) : "");
  }
  SampleSet Record(const Recording& recording, const std::vector<KnobValue>& values, int threads) const override;
  CellRecording RecordCell(const Cell& cell, const std::vector<KnobValue>& values) const override;
  std::string ConfigJson(const std::vector<KnobValue>& values) const override;
  double total_mass_kg() const override { return 10.0; }
  double leg_reach_m() const override { return 0.3; }
  bool level_ground() const override { return level; }
  bool plane_ground() const override { return level || sloped_plane; }

  // A recording with extras (the planted real set), `seed` its common random numbers.
  SampleSet RecordWith(const Recording& recording, const std::vector<KnobValue>& values, const FakeExtras& extras) const;
  int records() const { return records_; }
  // The `threads` of every Record call so far, in call order.
  std::vector<int> threads_seen() const {
    std::lock_guard<std::mutex> lock(mu_);
    return threads_seen_;
  }
  // Friction values below this topple the robot: the recording keeps one placement only.
  double topples_below_friction = 0;
  double topples_below_side_gain = 0;  // likewise for either side's gain
  // Rough ground: every execution at a placement shares an offset of this many noise sds, drawn
  // per (recording seed, placement): where the robot stands, which z does not tell.
  double ground_sd = 0;
  // Level ground: z is noise about the posture the payload's moments and the sides' gains give,
  // (pitch, roll) = (0.1 M x, 0.1 M y + 0.04 (left gain - right gain)) + extras' posture, instead
  // of the slope's tilt at the heading.
  bool level = false;
  double level_z_sd = 0.02;  // the noise of z about that posture (rad)
  // A slope that is a plane (else the fake's slope counts as uneven ground, where the posture is not
  // checked): z is the slope's tilt at the heading plus the posture above.
  bool sloped_plane = false;
  // The tilt steers the turn: x += tilt_steers turn (pitch, roll, 0), a slope of x in z that changes
  // sign with the command (a constant shift of z then reads as no tracker offset).
  double tilt_steers = 0;
  // How the payload acts (FakePayload); the default is linear in its mass and moments.
  FakePayload payload;
  // A chaotic walk (0 to 1): a recording at any other knob values than the nominal walks its own
  // way, its noise e replaced by sqrt(1 - a^2) e + a e', e' ~ N(0, 1) drawn from the recording's seed
  // and knob values: the same spread, paired executions sqrt(2 - 2 sqrt(1 - a^2)) sds apart.
  double walk_chaos = 0;
  // The simulator's nominal recording (every knob at its nominal value) goes this much further in
  // dx (m) than any other: one unlucky draw of a chaotic walk that a negligibly different recording
  // does not repeat. Record only (the planted real sets of RecordWith walk as the knobs say).
  double nominal_luck = 0;
  // Record as many executions per placement as the recording asks for (else always 5, the
  // protocol's own number, whatever it asks for).
  bool honour_executions = false;
  int cells() const { return cells_; }

 private:
  std::vector<Knob> knobs_;
  double friction_threshold_ = 0;
  mutable std::atomic<int> records_{0}, cells_{0};
  mutable std::mutex mu_;
  mutable std::vector<int> threads_seen_;
};

}  // namespace dgmm::sim2real::test

#include "sim2real/analysis.h"

namespace dgmm::sim2real::test {

// A sim set (the fake at nominal, recording seed `seed`) and a "real" set (another seed, the
// planted knob values and extras), both of the fake's own protocol.
struct FakePair {
  SampleSet sim, real;
};
FakePair MakeFakePair(const FakeSimulator& simulator, const std::vector<KnobValue>& planted,
                      const FakeExtras& extras = {}, std::uint64_t seed = 7);

// Analysis options for tests: no cache, fewer permutations and resamples, `threads` threads.
AnalysisOptions FastOptions(int threads = 1);

}  // namespace dgmm::sim2real::test
