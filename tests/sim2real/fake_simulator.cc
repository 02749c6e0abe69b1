#include "tests/sim2real/fake_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "util/error.h"

namespace dgmm::sim2real::test {
namespace {

constexpr double kSlopeRad = 0.3;
const Eigen::Vector3d kNoiseSd(0.01, 0.01, 0.02);

// The 12 commands of the fake protocol: (long, lat, turn) in {-0.5, 0, 0.5} on one axis at a
// time, and four mixed ones.
Eigen::MatrixXd Commands() {
  Eigen::MatrixXd c(12, 3);
  c << 0.5, 0, 0, -0.5, 0, 0, 0, 0.5, 0, 0, -0.5, 0, 0, 0, 0.5, 0, 0, -0.5, 0.5, 0.5, 0, 0.5, -0.5, 0, 0.5, 0, 0.5,
      -0.5, 0, -0.5, 0.5, 0.5, 0.5, -0.5, -0.5, 0;
  return c;
}

Knob MakeKnob(const std::string& name, const std::string& family, double nominal, double lo, double hi,
              std::vector<double> probes, Knob::Role role = Knob::Role::kShift) {
  Knob k;
  k.name = name, k.family = family, k.nominal = nominal, k.lo = lo, k.hi = hi, k.probes = probes, k.role = role;
  k.physical_min = 0;
  return k;
}

struct Values {
  double v[kNumFakeKnobs];
};

Values ValuesOf(const std::vector<Knob>& knobs, const std::vector<KnobValue>& values) {
  Values out;
  for (int k = 0; k < kNumFakeKnobs; ++k) out.v[k] = knobs[k].nominal;
  bool mass = false, position = false;
  for (const auto& kv : values) {
    if (kv.knob < 0 || kv.knob >= kNumFakeKnobs) throw MakeInputError("fake simulator", "knob", "out of range");
    // As lib/sim's config check: a knob at a value that is not a finite number is refused.
    if (!std::isfinite(kv.value)) throw MakeInputError("fake simulator", knobs[kv.knob].name, "expected a finite value");
    out.v[kv.knob] = kv.value;
    mass |= kv.knob == kPayloadMass;
    position |= kv.knob == kPayloadX || kv.knob == kPayloadY;
  }
  // As lib/sim's payload knobs: a position without a mass places the probe mass there.
  if (position && !mass) out.v[kPayloadMass] = knobs[kPayloadMass].probes[0];
  return out;
}

// u in [-1, 1] drawn from v's value alone (FakePayload::chaos).
double Chance(double v) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  std::mt19937_64 rng(bits);
  return std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
}

Eigen::Vector3d Gravity(double pitch, double roll) {
  return {std::sin(pitch), -std::sin(roll) * std::cos(pitch), -std::cos(roll) * std::cos(pitch)};
}

// The mean pose change of one execution.
Eigen::Vector3d Mean(const Values& k, const Eigen::Vector3d& c, double pitch, double roll, bool first,
                     const FakeExtras& extras, double friction_threshold, const FakePayload& payload) {
  const Eigen::Vector3d g = Gravity(pitch, roll);
  Eigen::Vector3d x(0.2 * c(0) + 0.05 * g(0) * std::abs(c(0)), 0.15 * c(1) + 0.04 * g(1) * std::abs(c(1)),
                    0.3 * c(2) + 0.02 * g(1));
  const double slip = friction_threshold > 0 ? 2 * std::max(0.0, friction_threshold - k.v[kFriction])
                                             : (1 - k.v[kFriction]) + 0.5 * (1 - k.v[kFriction]) * (1 - k.v[kFriction]);
  x += slip * Eigen::Vector3d(0.15 * g(0), 0.15 * g(1), 0.0);
  const double left = 1 - k.v[kLeftGain], right = 1 - k.v[kRightGain];
  x += (left - right) * Eigen::Vector3d(0, 0.02 * c(0), 0.12 * c(0) + 0.02);
  x -= (left + right) * Eigen::Vector3d(0.08 * c(0), 0.06 * c(1), 0.1 * c(2));
  for (int leg = 0; leg < 4; ++leg) {
    const double w = 1 - k.v[kLeg0Gain + leg];
    const double side = leg < 2 ? 1 : -1, front = leg % 2 == 0 ? 1 : -1;
    x += w * Eigen::Vector3d(-0.03 * c(0) + 0.01 * front * g(0), side * (0.01 * c(0) + 0.015 * front * c(2)),
                             side * (0.05 * c(0) + 0.01) + 0.03 * front * c(1));
  }
  if (first) x *= 1 - k.v[kLatency] / 0.1;  // motion lost at the first execution after a command change
  // The mass's own effect (payload.power bends it); the offsets' go with the moments M x and M y,
  // as gravity's torque does, or the forward offset's with the offset alone.
  const double luck = 1 + payload.chaos * Chance(k.v[kPayloadMass]);
  const double m = luck * payload.gain * std::pow(k.v[kPayloadMass], payload.power);
  const double torque = luck * payload.gain * k.v[kPayloadMass];
  const double forward = payload.offset_alone ? luck * 2.5 * payload.gain : torque;  // 2.5: the fake's usual mass
  x += m * Eigen::Vector3d(-0.01 * std::abs(c(0)), 0.01 * g(1), 0);
  x += torque * Eigen::Vector3d(0.02 * k.v[kPayloadY] * g(0), 0.05 * k.v[kPayloadY] * std::abs(c(0)),
                                0.2 * k.v[kPayloadY] * c(0));
  x.z() += forward * (-0.1 * k.v[kPayloadX] * c(2) + payload.bend * std::abs(k.v[kPayloadX]) * c(0));
  x += extras.tracker_bias;
  x += extras.geometry * Eigen::Vector3d(-std::abs(c(2)), c(0) * (1 + 2 * roll), 0);
  return x;
}

// The torso's tilt on level ground (FakeSimulator::level), and about the slope's (sloped_plane).
Eigen::Vector2d Posture(const Values& k, const FakeExtras& extras) {
  const double m = k.v[kPayloadMass];
  return Eigen::Vector2d(0.1 * m * k.v[kPayloadX], 0.1 * m * k.v[kPayloadY] + 0.04 * (k.v[kLeftGain] - k.v[kRightGain])) +
         extras.posture;
}

// Placement p of a recording: its command (the protocol cycles every command over 6 headings).
void Placement(std::uint64_t seed, int p, std::mt19937_64* rng, int* command, double* heading) {
  rng->seed(seed * 1000003 + p);
  *command = p % 12;
  *heading = (p / 12) % 6 * M_PI / 3 + std::uniform_real_distribution<double>(-0.2, 0.2)(*rng);
}

// The seed of a chaotic walk's own way at knob values k (0 at the nominal: it walks as always).
std::uint64_t WalkOfValues(const std::vector<Knob>& knobs, const Values& k, std::uint64_t seed) {
  std::uint64_t h = 0;
  for (int j = 0; j < kNumFakeKnobs; ++j) {
    if (k.v[j] == knobs[j].nominal) continue;
    std::uint64_t bits = 0;
    std::memcpy(&bits, &k.v[j], sizeof bits);
    h = (h ^ (bits + 0x9e3779b97f4a7c15ULL * (j + 1))) * 0x100000001b3ULL;
  }
  return h == 0 ? 0 : h ^ (seed * 0xbf58476d1ce4e5b9ULL);
}

}  // namespace

FakeSimulator::FakeSimulator() {
  knobs_ = {MakeKnob("floor.friction", "friction", 1, 0.3, 1.5, {0.6}),
            MakeKnob("actuators.side.left.gain", "actuator_gain", 1, 0.1, 1.5, {0.5}),
            MakeKnob("actuators.side.right.gain", "actuator_gain", 1, 0.1, 1.5, {0.5}),
            MakeKnob("actuators.leg0.gain", "actuator_gain", 1, 0.05, 1.5, {0.5}),
            MakeKnob("actuators.leg1.gain", "actuator_gain", 1, 0.05, 1.5, {0.5}),
            MakeKnob("actuators.leg2.gain", "actuator_gain", 1, 0.05, 1.5, {0.5}),
            MakeKnob("actuators.leg3.gain", "actuator_gain", 1, 0.05, 1.5, {0.5}),
            MakeKnob("actuators.latency_s", "latency", 0, 0, 0.08, {0.04}),
            MakeKnob("payload.mass_kg", "payload", 0, 0, 5, {1.5}, Knob::Role::kPayloadMass),
            MakeKnob("payload.x_m", "payload", 0, -0.2, 0.2, {0.1}, Knob::Role::kPayloadX),
            MakeKnob("payload.y_m", "payload", 0, -0.2, 0.2, {0.1}, Knob::Role::kPayloadY),
            MakeKnob("tracker.noise_scale", "tracker_noise", 1, 0.5, 4, {2}, Knob::Role::kSpread),
            MakeKnob("floor.friction.torsional", "friction", 0.01, 0, 0.1, {0.05})};
  knobs_[kPayloadX].physical_min = knobs_[kPayloadY].physical_min = -INFINITY;
  knobs_[kLeftGain].side = "left", knobs_[kRightGain].side = "right";
  knobs_[kLeftGain].members = {"leg0", "leg1"}, knobs_[kRightGain].members = {"leg2", "leg3"};
  for (int leg = 0; leg < 4; ++leg) knobs_[kLeg0Gain + leg].leg = "leg" + std::to_string(leg);
}

FakeSimulator::FakeSimulator(double friction_threshold, std::vector<double> friction_probes) : FakeSimulator() {
  friction_threshold_ = friction_threshold;
  knobs_[kFriction].probes = std::move(friction_probes);
}

SampleSet FakeSimulator::Record(const Recording& recording, const std::vector<KnobValue>& values, int threads) const {
  {
    std::lock_guard<std::mutex> lock(mu_);
    threads_seen_.push_back(threads);
  }
  SampleSet s = RecordWith(recording, values, FakeExtras{});
  const bool nominal = std::all_of(values.begin(), values.end(),
                                   [&](const KnobValue& v) { return v.value == knobs_[v.knob].nominal; });
  if (nominal_luck != 0 && nominal) s.x.col(0).array() += nominal_luck;
  return s;
}

SampleSet FakeSimulator::RecordWith(const Recording& recording, const std::vector<KnobValue>& values,
                                    const FakeExtras& extras) const {
  if (recording.protocol != "paper") throw MakeInputError("fake simulator", "protocol", "expected paper");
  ++records_;
  const Values k = ValuesOf(knobs_, values);
  const int placements = recording.placements > 0 ? recording.placements : 72;
  SampleSet s;
  s.commands = Commands();
  s.command_dim_names = {"long", "lat", "turn"};
  for (int c = 0; c < 12; ++c) {
    char label[48];
    std::snprintf(label, sizeof label, "%+.1f,%+.1f,%+.1f", s.commands(c, 0), s.commands(c, 1), s.commands(c, 2));
    s.command_labels.push_back(label);
  }
  const int executions = honour_executions && recording.executions_per_placement > 0 ? recording.executions_per_placement : 5;
  const int n = executions * placements;
  s.command.resize(n), s.episode.resize(n), s.step.resize(n);
  s.x.resize(n, 3), s.z.resize(n, 2);
  std::mt19937_64 rng;
  std::normal_distribution<double> unit(0, 1);
  const std::uint64_t way = walk_chaos != 0 ? WalkOfValues(knobs_, k, recording.seed) : 0;
  std::mt19937_64 own_way(way);
  for (int p = 0; p < placements; ++p) {
    int c;
    double heading;
    Placement(recording.seed, p, &rng, &c, &heading);
    Eigen::Vector3d stands = Eigen::Vector3d::Zero();
    if (ground_sd > 0) {
      std::mt19937_64 ground(recording.seed * 7919 + p);
      std::normal_distribution<double> place(0, ground_sd);
      for (int j = 0; j < 3; ++j) stands(j) = kNoiseSd(j) * place(ground);
    }
    for (int e = 0; e < executions; ++e) {
      const int i = executions * p + e;
      const Eigen::Vector2d slope = kSlopeRad * Eigen::Vector2d(std::cos(heading), std::sin(heading));
      const Eigen::Vector2d tilt = level ? Posture(k, extras) : sloped_plane ? slope + Posture(k, extras) : slope;
      const double z_sd = level ? level_z_sd : 0.02;
      const double pitch = tilt(0) + z_sd * unit(rng);
      const double roll = tilt(1) + z_sd * unit(rng);
      Eigen::Vector3d noise(unit(rng), unit(rng), unit(rng));
      if (way != 0) {  // the walk's own way: as much noise, a share walk_chaos of it unpaired
        const Eigen::Vector3d chance(unit(own_way), unit(own_way), unit(own_way));
        noise = std::sqrt(1 - walk_chaos * walk_chaos) * noise + walk_chaos * chance;
      }
      s.command(i) = c, s.episode(i) = p, s.step(i) = e;
      s.z.row(i) << pitch + extras.imu_offset(0), roll + extras.imu_offset(1);
      const Eigen::Vector2d felt = Eigen::Vector2d(pitch, roll) + extras.motion_tilt;
      const Eigen::Vector3d command = s.commands.row(c).transpose();
      s.x.row(i) = (Mean(k, command, felt(0), felt(1), e == 0, extras, friction_threshold_, payload) +
                    tilt_steers * Eigen::Vector3d(felt(0) * command(2), felt(1) * command(2), 0) +
                    k.v[kTrackerNoise] * kNoiseSd.cwiseProduct(noise) + stands).transpose();
    }
  }
  s.x_names = {"dx", "dy", "dyaw"};
  s.x_units = {"m", "m", "rad"};
  s.z_names = {"pitch", "roll"};
  s.z_units = {"rad", "rad"};
  s.source = "fake simulator";
  s.metadata["protocol"] = recording.protocol;
  s.metadata["seed"] = std::to_string(recording.seed);
  if (k.v[kFriction] < topples_below_friction || std::min(k.v[kLeftGain], k.v[kRightGain]) < topples_below_side_gain) {
    return s.Subset({0, 1, 2, 3, 4});
  }
  return s;
}

CellRecording FakeSimulator::RecordCell(const Cell& cell, const std::vector<KnobValue>& values) const {
  ++cells_;
  const Values k = ValuesOf(knobs_, values);
  CellRecording out;
  const int n = cell.placements * cell.executions_per_placement;
  out.set.commands = cell.command.transpose();
  out.set.command.setZero(n), out.set.episode.resize(n), out.set.step.resize(n);
  out.set.x.resize(n, 3), out.set.z.resize(n, 2);
  std::mt19937_64 rng(cell.seed);
  std::normal_distribution<double> unit(0, 1);
  for (int i = 0; i < n; ++i) {
    out.set.episode(i) = i / cell.executions_per_placement, out.set.step(i) = i % cell.executions_per_placement;
    const double pitch = cell.terrain(0) + 0.01 * unit(rng), roll = cell.terrain(1) + 0.01 * unit(rng);
    Eigen::Vector3d noise(unit(rng), unit(rng), unit(rng));
    out.set.z.row(i) << pitch, roll;
    out.set.x.row(i) = (Mean(k, cell.command, pitch, roll, out.set.step(i) == 0, FakeExtras{}, friction_threshold_,
                            payload) +
                        k.v[kTrackerNoise] * kNoiseSd.cwiseProduct(noise)).transpose();
  }
  out.placement = "the fake plane";
  out.heading_deg = std::atan2(cell.terrain(1), cell.terrain(0)) * 180 / M_PI;
  return out;
}

std::string FakeSimulator::ConfigJson(const std::vector<KnobValue>& values) const {
  const Values k = ValuesOf(knobs_, values);
  std::string s = "{";
  for (int i = 0; i < kNumFakeKnobs; ++i) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s\"%s\": %.6g", i ? ", " : "", knobs_[i].name.c_str(), k.v[i]);
    s += buf;
  }
  return s + "}";
}

}  // namespace dgmm::sim2real::test

namespace dgmm::sim2real::test {

FakePair MakeFakePair(const FakeSimulator& simulator, const std::vector<KnobValue>& planted, const FakeExtras& extras,
                      std::uint64_t seed) {
  FakePair p;
  Recording sim{"paper", seed, 0};
  p.sim = simulator.Record(sim, {}, 1);
  Recording real{"paper", seed + 1000, 48};
  p.real = simulator.RecordWith(real, planted, extras);
  p.real.metadata.clear();
  p.real.source = "planted real";
  return p;
}

AnalysisOptions FastOptions(int threads) {
  AnalysisOptions o;
  o.locate.locate.mmd.permutations = 200;
  o.adequacy.locate.mmd.permutations = 200;
  o.adequacy.residual.permutations = 200;
  o.adequacy.drift.permutations = 200;
  o.refine.selection.bootstrap_selection = 10;
  o.refine.selection.bootstrap_parameters = 50;
  o.candidates.placements = 0;
  o.candidates.recording.cache_dir = "-";
  o.candidates.recording.threads = threads;
  o.ties.experiment.threads = threads;
  o.ties.experiment.permutations = 500;
  return o;
}

}  // namespace dgmm::sim2real::test
