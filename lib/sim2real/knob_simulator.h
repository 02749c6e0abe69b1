#pragma once
// What the sim-vs-real analysis needs of a simulator (docs/sim2real.md, "The simulator"): the
// physical parameters it can change (knobs) and paired re-recordings, at chosen knob values, of
// the sim set's own recording or of one command x terrain cell. Paired means common random
// numbers: a recording repeated at other knob values draws the same placements, commands and
// sensor noise, so the difference of two recordings is the knobs' effect alone.
//
// lib/sim2real never sees MuJoCo: the app wires this interface to lib/sim
// (app/wiring/mujoco_knob_simulator.h); tests of the analysis's logic use a fake.
#include <algorithm>
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/sample_set.h"

namespace dgmm::sim2real {

// One physical parameter of the simulation a user can get wrong, relative to the simulator's
// nominal (the model's own physics).
struct Knob {
  // How the analysis uses the knob's probes.
  enum class Role {
    kShift,        // its probe's paired difference is a mean-shift signature (one parameter)
    kPayloadMass,  // the payload's three-parameter effect: mass at the torso centre ...
    kPayloadX,     // ... its forward offset ...
    kPayloadY,     // ... and its leftward offset (the mass then sits at the probe mass)
    kSpread,       // a measurement noise scale: its probe gives a spread signature only
  };
  std::string name;    // unique, e.g. "floor.friction.sliding", "actuators.leg.front_left.gain"
  std::string family;  // friction, contact, mass, payload, actuator_gain, joint_damping, latency,
                       // backlash, tracker_noise, ... (the report aggregates by family)
  std::string unit;    // "" for a factor
  Role role = Role::kShift;
  double nominal = 0;           // the value of the nominal simulation
  double lo = 0, hi = 0;        // the range searched; a value pinned at either end is flagged
  double physical_min = -std::numeric_limits<double>::infinity();  // e.g. 0 for a mass or a gain
  std::vector<double> probes;   // values simulated for its signature
  std::string leg;              // the leg's name for a per-leg knob, else ""
  std::string side;             // "left" or "right" for a per-side knob, else ""
  std::vector<std::string> members;  // a per-side knob: the `leg` of every per-leg knob it scales
};

// v inside the knob's range and above its physical limit.
inline double WithinKnob(const Knob& k, double v) { return std::clamp(v, std::max(k.lo, k.physical_min), k.hi); }

// A knob (index into KnobSimulator::knobs()) at a value in its unit.
struct KnobValue {
  int knob = -1;
  double value = 0;
};

// Which recording to repeat: the sim set's protocol and seed, as its metadata names them.
struct Recording {
  std::string protocol;    // e.g. "paper", "paper-830"
  std::uint64_t seed = 0;
  int placements = 0;      // 0: the protocol's own number
  int executions_per_placement = 0;  // 0: the protocol's own number (paper: 5)
};

// One command x terrain cell of a discriminating experiment.
struct Cell {
  Eigen::VectorXd command;  // a row of the sim set's command table
  Eigen::VectorXd terrain;  // the z (the sim set's terrain columns) the robot should stand on
  int placements = 4;
  int executions_per_placement = 5;
  std::uint64_t seed = 0;
};

struct CellRecording {
  SampleSet set;
  std::string placement;  // where the simulator stood the robot to get the terrain, in words
  double heading_deg = std::numeric_limits<double>::quiet_NaN();  // when a heading gives it
};

class KnobSimulator {
 public:
  virtual ~KnobSimulator() = default;

  // The knobs, in a fixed order; KnobValue::knob indexes this list.
  virtual const std::vector<Knob>& knobs() const = 0;

  // Identifies every input of a simulation other than the recording and the knob values: the
  // model as compiled (included files, meshes, height fields), the config, the simulator's code
  // version. Equal fingerprints, recordings and values give equal sets (the key of a cache).
  virtual std::string Fingerprint() const = 0;

  // The recording at the knob values (empty: nominal). Thread-safe; may itself use up to
  // `threads` threads, with a result that does not depend on that number. Throws InputError
  // for an unknown protocol or a failed simulation.
  virtual SampleSet Record(const Recording& recording, const std::vector<KnobValue>& values,
                           int threads) const = 0;

  // The cell at the knob values. The placement is chosen from the cell alone (at the nominal
  // knobs), so two calls differing only in `values` are paired. Thread-safe.
  virtual CellRecording RecordCell(const Cell& cell, const std::vector<KnobValue>& values) const = 0;

  // The simulator's config with the knob values applied: a file a user re-simulates with.
  virtual std::string ConfigJson(const std::vector<KnobValue>& values) const = 0;

  // Is the ground level (a plane facing up, no slope, no height field)? Then the torso's posture
  // compares between sets of other placements (posture.h); false by default.
  virtual bool level_ground() const { return false; }
  // Is the ground a plane (level, or tilted by gravity to a slope; no height field)? On a slope the
  // posture compares by the radial part of z (posture.h, SlopeGeometry); level_ground() by default.
  virtual bool plane_ground() const { return level_ground(); }
  // Is gravity tilted to a slope, on a plane or a height field? Then the ground stage compares by
  // the radial part of z even where the ground's own tilts blur the slope's circle (ground_search.h);
  // false by default (the stage then asks the circle's fit alone).
  virtual bool sloped_ground() const { return false; }

  // Scales for constants relative to the robot: its total mass (kg), leg reach (m).
  virtual double total_mass_kg() const = 0;
  virtual double leg_reach_m() const = 0;
};

}  // namespace dgmm::sim2real
