#pragma once
// The physical parameters ("knobs") of a simulation a user can get wrong, enumerated from the
// loaded robot model and its SimConfig (not from hard-coded body names): floor friction, floor
// contact softness (solref) and impedance (solimp dmax, width), all-body mass scale, a payload on
// the torso, actuator gain per leg (legs = the torso's child subtrees that carry actuators), per
// side (sign of the leg root's y), of all legs (kp), joint damping, actuation latency, backlash,
// the ground's own shape (factors on the terrain block's roughness, stone and step heights, when
// it has them), and last the tracker's noise scale (when the config has tracker noise). Each knob knows its
// nominal value, a physical range, the probe values simulated for its signature (docs/sim2real.md,
// "Signatures from the simulator") and how to apply a value (to the SimConfig, or to the compiled
// mjModel through a ModelEdit).
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/protocol.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"

namespace dgmm::sim {

enum class KnobKind {
  kFrictionSliding,    // every geom's sliding friction (MuJoCo takes the max per contact)
  kFrictionTorsional,  // every geom's torsional friction [m]
  kFloorSolrefTime,    // floor geom solref[0], contact time constant [s]
  kFloorSolrefDamping, // floor geom solref[1], damping ratio
  kFloorSolimpDmax,    // floor geom solimp[1], impedance at depth (solimp[0] lowered to it if larger)
  kFloorSolimpWidth,   // floor geom solimp[2], penetration over which impedance goes dmin -> dmax [m]
  kMassScale,          // every body's mass and inertia scaled
  kPayloadMass,        // payload mass [kg] at the payload's position
  kPayloadX,           // payload x offset [m] (torso frame, forward)
  kPayloadY,           // payload y offset [m] (torso frame, left)
  kLegGain,            // kp scale of one leg (index = leg)
  kSideGain,           // kp scale of the legs on one side (index 0: left, y > 0; 1: right)
  kKpScale,            // kp scale of every leg actuator
  kDampingScale,       // joint damping scale of every leg hinge
  kLatency,            // actuation latency [s] (actuators.latency_s)
  kBacklash,           // gear-train free play of every leg joint [rad] (actuators.backlash_rad)
  kTrackerNoiseScale,  // factor on the four tracker sd's of config.noise (not the IMU's)
  kFrictionScale,      // factor on every geom's sliding friction (a robot block's robot)
  kGroundRoughness,    // factor on terrain.rough.rms_height_m (a config with terrain)
  kGroundStoneHeight,  // factor on terrain.stones.height_m
  kGroundStepHeight,   // factor on terrain.steps.height_m
};

// Confusion-matrix family of a knob (docs/sim2real.md, "report.json verdict").
struct Knob {
  KnobKind kind;
  int index = -1;            // leg or side for kLegGain / kSideGain
  std::string name;          // e.g. "floor.friction.sliding", "actuators.leg3.gain"
  std::string family;        // friction, contact, mass, payload, actuator_gain, joint_damping, latency,
                             // backlash, tracker_noise
  std::string unit;          // "" for factors
  double nominal = 0;        // value in the nominal config / model
  double lo = 0, hi = 0;     // physical range searched
  std::vector<double> probes;  // values simulated for the signature (one signature each)
  std::string leg;             // kLegGain: the leg's name ("leg3" for the built-in robot)
  std::vector<std::string> members;  // kSideGain: the side's leg names (the `leg` of its kLegGain knobs)
};

struct KnobValue {
  int knob = -1;  // index into the knob list
  double value = 0;
};

// A knob from its fields (probes: the values simulated for its signature).
Knob MakeKnob(KnobKind kind, int index, std::string name, std::string family, std::string unit,
              double nominal, double lo, double hi, std::vector<double> probes);

// Knobs of the robot of `config` (loads its MJCF). Throws InputError when it cannot be loaded.
std::vector<Knob> EnumerateKnobs(const SimConfig& config);

// The config with the config-level knob values applied, and the model edit for the rest.
// The payload knobs: a mass at the centre unless kPayloadX/Y give an offset (with no
// kPayloadMass, the offsets carry `payload_probe_kg`).
SimConfig ApplyKnobs(const SimConfig& config, const std::vector<Knob>& knobs,
                     const std::vector<KnobValue>& values, ModelEdit* edit);

// The same for a config with a robot block (robot_knobs.cc; EnumerateKnobs and ApplyKnobs call
// them): factors on the model's own values (every geom's friction, every body's mass, the leg
// servos' gains and the leg joints' damping), a payload on the torso as a fraction of the model's
// total mass at offsets relative to the leg reach, per-leg gains named by leg name, per-side gains
// by the side rule of legged_robot.h, the floor's contact parameters and the tracker's noise.
std::vector<Knob> EnumerateRobotKnobs(const SimConfig& config);
SimConfig ApplyRobotKnobs(const SimConfig& config, const std::vector<Knob>& knobs,
                          const std::vector<KnobValue>& values, ModelEdit* edit);

// SimulateProtocol with the knobs set (same seed: paired with the nominal run).
SampleSet SimulateWithKnobs(const SimConfig& config, const ProtocolOptions& options,
                            const std::vector<Knob>& knobs, const std::vector<KnobValue>& values);

// The MJCF text of the robot of `config` (the built-in one when mjcf_path is empty), e.g. to key
// a cache of simulations. Throws InputError when the file cannot be read.
std::string RobotMjcfText(const SimConfig& config);

// Mass of the payload probes [kg]: 15% of the robot's mass (the model's, with a robot block).
double PayloadProbeMass(const SimConfig& config);

// The floor's contact softness shared by every robot (family "contact"): solref's time constant
// and damping ratio as knobs when the floor geom uses the standard (positive time constant) form.
void AddFloorSolrefKnobs(const mjModel_* m, int floor, std::vector<Knob>* knobs);
// The measurement-side knob shared by every robot: appends tracker.noise_scale when config.noise
// has any tracker noise, and applies a value of it (the four tracker sd's of `config` scaled into
// out->noise; the IMU's untouched).
void AddTrackerNoiseKnob(const SimConfig& config, std::vector<Knob>* knobs);
// The ground's knobs shared by every robot (family "ground"): a factor in [0, 3] on each terrain
// feature the config has (terrain.rough.rms_scale, terrain.stones.height_scale,
// terrain.steps.height_scale); none on the plane. ApplyGroundKnob sets one on `out`.
void AddGroundKnobs(const SimConfig& config, std::vector<Knob>* knobs);
void ApplyGroundKnob(const SimConfig& config, KnobKind kind, double factor, SimConfig* out);
void ScaleTrackerNoise(const SimConfig& config, double factor, SimConfig* out);

}  // namespace dgmm::sim
