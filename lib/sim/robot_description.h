#pragma once
// A legged robot described as data (the optional `robot` block of a simulation config): which
// MJCF parts are the torso, the floor and each leg, and how the generic gait drives them. A config
// with this block is simulated with the model's own physics (docs/simulation.md, "Bring your own
// robot"); without it, the built-in eight-legged conventions of sim_config.h apply unchanged.
// Plain data: no MuJoCo here (the model is checked against it in robot_model.h).
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

namespace dgmm::sim {

// Where a leg touches the ground: a site, a geom, or a point in a body's frame.
struct FootDescription {
  std::string site, geom, body;                          // exactly one is set
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();    // with `body` only
};

struct LegDescription {
  std::string name;                     // e.g. "front_left"; unique; names per-leg knobs
  std::vector<std::string> joints;      // the leg's hinge/slide joints, torso to foot
  std::vector<std::string> actuators;   // one per joint; empty: the actuator driving each joint
  FootDescription foot;
  std::string side;                     // "left", "right" or "" (taken from the geometry)
};

// Timing of the generic gait: each leg's phase in [0, 1) of the cycle and the duty factor (share
// of the cycle a foot is on the ground). Named tables exist for 4, 6 and 8 legs
// (gait_table.h); "custom" takes `phases`.
struct GaitDescription {
  // auto | trot | crawl | tripod | tetrapod | wave | alternating | alternating_tetrapod | custom
  std::string pattern = "auto";
  std::vector<double> phases;    // custom: one per leg, in the order of `legs`
  double duty_factor = 0;        // (0, 1); 0: the pattern's own
  double period_s = 0.6;         // one full cycle
  // Lengths relative to the robot's leg reach (the longest torso-to-foot chain at the model's
  // rest pose) unless the *_m field is set (> 0).
  double stride_reach = 0.3;     // torso travel per cycle at |command| = 1
  double stride_m = 0;
  double step_height_reach = 0.15;
  double step_height_m = 0;
  double stance_height_reach = 0;  // torso above the feet; 0: the model's rest pose, 90% extended
  double stance_height_m = 0;
  double turn_rad = 0.3;           // yaw per cycle at |turn| = 1
  // Share of the way the feet shift to keep the support polygon under the centre of mass on a
  // slope: by lean x h tan(slope) along the ground's tilt at the robot's heading (h the stance
  // height). 0: feet where the gait puts them, whatever the ground.
  double lean = 1.0;
  // Share of the torso's tilt from the slope plane (its heading kept) that the feet's targets take
  // back at every control step (generic_walker.h, LevelBack). 0: the targets stay in the torso
  // frame whatever its tilt, which a plane corrects by itself but uneven ground does not (the
  // hexapod on its rough ground: 41% of samples tilted beyond 25 degrees from upright at 0, 10% at
  // 0.75; at 1 the loop runs against the servos' lag and the robot falls). Not for every robot:
  // it takes from a trotting torso what pushes it back to level (the planar quadruped falls from
  // 0.25, the sprawled one stands twice as tilted at 0.75). The protocol's tilt warning
  // (kTiltedDeg, protocol.h: from the ground's plane) says whether a robot needs it.
  double level = 0;
  // Body sway of statically stable gaits: while a leg swings the torso moves `sway` of the way
  // towards the centroid of the other legs' stance points (blended from one swing to the next).
  // Negative (-1): the default, 0.1 for a duty factor of 0.75 or more and 0 below (ResolveSway).
  double sway = -1;
  // Stance legs' targets offset by the joint torques that carry the robot's weight over the
  // servos' stiffness (servo_feedforward.h), so soft position servos do not sag and drift.
  bool servo_feedforward = false;
};

// What drives the legs: the generic gait (foot placement through inverse kinematics), or a
// replay of recorded actuator signals, one CSV per command: a column `t` (s, increasing from 0)
// and one column per actuator of the model (by name), linearly interpolated and repeated with the
// recording's length as period. `signal` says what the values are: position targets (servos)
// or forces/torques (motors, tendons). Either way they pass the config's latency and backlash.
struct ReplayRecording {
  Eigen::Vector3d command = Eigen::Vector3d::Zero();  // (long, lat, turn)
  std::string file;                                   // relative to the config file's folder
};

struct ControllerDescription {
  std::string type = "gait";        // gait | replay
  std::string signal = "position";  // replay: position | torque
  std::vector<ReplayRecording> recordings;
  bool replay() const { return type == "replay"; }
};

struct RobotDescription {
  std::string torso_body = "torso";
  std::string floor_geom = "floor";
  Eigen::Vector3d forward_axis = Eigen::Vector3d::UnitX();  // torso frame
  std::vector<LegDescription> legs;
  std::vector<std::string> passive_joints;  // joints deliberately left undriven
  // Driven joints of no leg (a spine between body segments, a neck, a tail): the generic gait
  // holds each at its rest value (the first keyframe, else qpos0); a replay drives them as recorded.
  std::vector<std::string> held_joints;
  GaitDescription gait;
  std::map<std::string, double> leg_gain;   // by leg name: scales the leg's actuator gains
  ControllerDescription controller;
  // The model's physics is the nominal; true applies the config's friction, masses, gains and
  // damping over it (the built-in robot's behaviour).
  bool overwrite_physics = false;
};

// Parses the `robot` block (JSON text of one object). Unknown keys, missing names, duplicate leg
// names and bad numbers are InputError "<source>: robot.<field>: <problem>".
RobotDescription RobotDescriptionFromJson(const std::string& json_text, const std::string& source);
// The block as a JSON object text (round-trips through RobotDescriptionFromJson).
std::string RobotDescriptionToJson(const RobotDescription& robot);

}  // namespace dgmm::sim
