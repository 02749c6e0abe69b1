// Knobs of a robot described by a config's robot block (knobs.h): factors on the model's own
// physics, scaled by the model (total mass, leg reach), per-leg knobs named by leg name.
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "sim/knobs.h"
#include "sim/legged_robot.h"
#include "sim/sim_config.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

// Per-leg gains (probe half the leg's gain) and per-side gains, probed at 0.4: the side probes
// decide whether the per-leg probes are recorded at all (lib/sim2real/candidates.h), and at 0.6 a
// leg at half its gain on the hexapod did not show through its side.
void AddLegKnobs(const SimConfig& config, const LeggedRobot& bound, std::vector<Knob>* knobs) {
  Knob side[2] = {MakeKnob(KnobKind::kSideGain, 0, "actuators.left_side.gain", "actuator_gain", "", 1.0, 0.05, 1.5, {0.4}),
                  MakeKnob(KnobKind::kSideGain, 1, "actuators.right_side.gain", "actuator_gain", "", 1.0, 0.05, 1.5,
                       {0.4})};
  for (int i = 0; i < static_cast<int>(bound.legs.size()); ++i) {
    const std::string& name = bound.legs[i].name;
    const auto it = config.robot->leg_gain.find(name);
    const double g = it == config.robot->leg_gain.end() ? 1.0 : it->second;
    knobs->push_back(MakeKnob(KnobKind::kLegGain, i, "actuators." + name + ".gain", "actuator_gain", "", g, 0.05 * g,
                          1.5 * g, {0.5 * g}));
    knobs->back().leg = name;
    side[bound.legs[i].side > 0 ? 0 : 1].members.push_back(name);
  }
  for (auto& s : side) {
    if (!s.members.empty()) knobs->push_back(s);
  }
}

// Latency of every actuator signal (probe: 7% of the gait cycle; range up to a third of the cycle,
// 0.2 s at the least), and backlash of the joint servos when the robot has any (a torque replay
// has none).
void AddActuationKnobs(const SimConfig& config, const mjModel* m, std::vector<Knob>* knobs) {
  const double lat = config.actuators.latency_s;
  const double hi = MaxLatencyS(config);
  const double probe = std::min(hi, lat + 0.07 * config.robot->gait.period_s);
  knobs->push_back(MakeKnob(KnobKind::kLatency, -1, "actuators.latency_s", "latency", "s", lat, 0.0, hi, {probe}));
  bool servos = false;
  for (int a = 0; a < m->nu; ++a) {
    servos |= m->actuator_trntype[a] == mjTRN_JOINT && IsPositionServo(m, a);
  }
  if (!servos) return;
  const double bl = config.actuators.backlash_rad;
  knobs->push_back(MakeKnob(KnobKind::kBacklash, -1, "actuators.backlash_rad", "backlash", "rad", bl, 0.0, 0.2,
                            {bl + 0.03 <= 0.2 ? bl + 0.03 : bl - 0.03}));
}

// What ApplyRobotKnobs collects from the values before building the model edit.
struct RobotEdit {
  double friction = 1, mass = 1, kp = 1, damping = 1;
  double solref_time = NAN, solref_damp = NAN;
  bool any() const {
    return friction != 1 || mass != 1 || kp != 1 || damping != 1 || std::isfinite(solref_time) ||
           std::isfinite(solref_damp);
  }
};

ModelEdit MakeEdit(const SimConfig& config, const RobotEdit& e) {
  const RobotDescription robot = *config.robot;
  return [robot, e](mjModel_* m) {
    for (int g = 0; g < m->ngeom; ++g) m->geom_friction[3 * g] *= e.friction;
    for (int b = 1; b < m->nbody; ++b) {
      m->body_mass[b] *= e.mass;
      for (int k = 0; k < 3; ++k) m->body_inertia[3 * b + k] *= e.mass;
    }
    for (const auto& leg : robot.legs) {
      for (const auto& joint : leg.joints) {
        const int j = mj_name2id(m, mjOBJ_JOINT, joint.c_str());
        if (j < 0) continue;
        m->dof_damping[m->jnt_dofadr[j]] *= e.damping;
        for (int a = 0; a < m->nu; ++a) {
          if (m->actuator_trntype[a] != mjTRN_JOINT || m->actuator_trnid[2 * a] != j) continue;
          m->actuator_gainprm[mjNGAIN * a] *= e.kp;
          m->actuator_biasprm[mjNBIAS * a + 1] *= e.kp;
        }
      }
    }
    const int floor = mj_name2id(m, mjOBJ_GEOM, robot.floor_geom.c_str());
    if (floor >= 0 && std::isfinite(e.solref_time)) m->geom_solref[mjNREF * floor + 0] = e.solref_time;
    if (floor >= 0 && std::isfinite(e.solref_damp)) m->geom_solref[mjNREF * floor + 1] = e.solref_damp;
  };
}

}  // namespace

std::vector<Knob> EnumerateRobotKnobs(const SimConfig& config) {
  const std::string source = config.mjcf_path.empty() ? "built-in robot" : config.mjcf_path;
  MjModelPtr model = LoadRobotModel(config);
  const LeggedRobot bound = BindRobot(model.get(), *config.robot, source);
  const mjModel* m = model.get();
  const double total_kg = mj_getTotalmass(m);
  const double reach = bound.reach_m;
  std::vector<Knob> knobs;
  // Friction probed down to 0.35: slipping is the usual mismatch, and from 0.6 alone the signature
  // under-predicted a factor of 0.35 so far that a wider tracker noise won the first step
  // (docs/simulation.md, "sim2real on a robot block's robot").
  knobs.push_back(MakeKnob(KnobKind::kFrictionScale, -1, "geoms.friction_scale", "friction", "", 1.0, 0.2, 2.0, {0.35, 0.6, 1.5}));
  if (bound.floor_geom >= 0) AddFloorSolrefKnobs(m, bound.floor_geom, &knobs);
  knobs.push_back(MakeKnob(KnobKind::kMassScale, -1, "bodies.mass_scale", "mass", "", 1.0, 0.4, 2.5, {0.7, 1.4}));
  const double probe_kg = 0.15 * total_kg;
  const auto& p = config.payload;
  knobs.push_back(MakeKnob(KnobKind::kPayloadMass, -1, "payload.mass_kg", "payload", "kg", p.mass_kg, 0.0, 4 * probe_kg,
                       {p.mass_kg + probe_kg}));
  knobs.push_back(MakeKnob(KnobKind::kPayloadX, -1, "payload.position_x_m", "payload", "m", p.position_body_m.x(), -0.6 * reach,
                       0.6 * reach, {0.2 * reach}));
  knobs.push_back(MakeKnob(KnobKind::kPayloadY, -1, "payload.position_y_m", "payload", "m", p.position_body_m.y(), -0.4 * reach,
                       0.4 * reach, {0.15 * reach}));
  AddLegKnobs(config, bound, &knobs);
  knobs.push_back(MakeKnob(KnobKind::kKpScale, -1, "actuators.kp_scale", "actuator_gain", "", 1.0, 0.2, 2.5, {0.6, 1.5}));
  knobs.push_back(MakeKnob(KnobKind::kDampingScale, -1, "joints.damping_scale", "joint_damping", "", 1.0, 0.05, 10.0,
                       {0.25, 4.0}));
  AddActuationKnobs(config, m, &knobs);
  AddGroundKnobs(config, &knobs);
  AddTrackerNoiseKnob(config, &knobs);
  return knobs;
}

SimConfig ApplyRobotKnobs(const SimConfig& config, const std::vector<Knob>& knobs,
                          const std::vector<KnobValue>& values, ModelEdit* edit) {
  SimConfig c = config;
  RobotEdit e;
  bool payload = false;
  double payload_kg = NAN;
  for (const auto& v : values) {
    const Knob& k = knobs.at(v.knob);
    switch (k.kind) {
      case KnobKind::kFrictionScale: e.friction = v.value; break;
      case KnobKind::kMassScale: e.mass = v.value; break;
      case KnobKind::kKpScale: e.kp = v.value; break;
      case KnobKind::kDampingScale: e.damping = v.value; break;
      case KnobKind::kFloorSolrefTime: e.solref_time = v.value; break;
      case KnobKind::kFloorSolrefDamping: e.solref_damp = v.value; break;
      // The payload is the experiment's (config.payload, applied by legged_robot.h).
      case KnobKind::kPayloadMass: payload = true; payload_kg = v.value; break;
      case KnobKind::kPayloadX: payload = true; c.payload.position_body_m.x() = v.value; break;
      case KnobKind::kPayloadY: payload = true; c.payload.position_body_m.y() = v.value; break;
      case KnobKind::kLegGain: c.robot->leg_gain[k.leg] = v.value; break;
      case KnobKind::kLatency: c.actuators.latency_s = v.value; break;
      case KnobKind::kBacklash: c.actuators.backlash_rad = v.value; break;
      case KnobKind::kSideGain:
        for (const auto& leg : k.members) {
          const auto it = config.robot->leg_gain.find(leg);
          c.robot->leg_gain[leg] = (it == config.robot->leg_gain.end() ? 1.0 : it->second) * v.value;
        }
        break;
      case KnobKind::kTrackerNoiseScale: ScaleTrackerNoise(config, v.value, &c); break;
      case KnobKind::kGroundRoughness:
      case KnobKind::kGroundStoneHeight:
      case KnobKind::kGroundStepHeight: ApplyGroundKnob(config, k.kind, v.value, &c); break;
      default:
        throw MakeInputError(config.mjcf_path, k.name, "not a knob of a robot block's robot");
    }
  }
  // Offsets alone carry the probe mass (as for the built-in robot).
  if (payload) c.payload.mass_kg = std::isfinite(payload_kg) ? payload_kg : std::max(config.payload.mass_kg, PayloadProbeMass(config));
  if (edit) *edit = e.any() ? MakeEdit(config, e) : ModelEdit{};
  return c;
}

}  // namespace dgmm::sim
