#include "sim/knobs.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "sim/mujoco_model.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

// The child of `torso` whose subtree holds `body` (-1 when it is not below the torso).
int TorsoChildOf(const mjModel* m, int body, int torso) {
  while (body > 0 && m->body_parentid[body] != torso) body = m->body_parentid[body];
  return body > 0 ? body : -1;
}

// Largest |x| and |y| of the leg roots (the torso's children carrying the leg actuators) in the
// torso frame; one falls back on the other when it is under 1 cm (legs in one line).
Eigen::Vector2d LegRootSpan(const mjModel* m, const RobotParts& parts) {
  Eigen::Vector2d span = Eigen::Vector2d::Zero();
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const int joint = m->actuator_trnid[2 * parts.actuator[leg][0]];
    const int root = TorsoChildOf(m, m->jnt_bodyid[joint], parts.torso_body);
    if (root < 0) continue;
    span = span.cwiseMax(Eigen::Vector2d(std::abs(m->body_pos[3 * root]), std::abs(m->body_pos[3 * root + 1])));
  }
  if (span.x() < 0.01) span.x() = span.y();
  if (span.y() < 0.01) span.y() = span.x();
  return span.cwiseMax(0.01);
}

}  // namespace

Knob MakeKnob(KnobKind kind, int index, std::string name, std::string family, std::string unit,
              double nominal, double lo, double hi, std::vector<double> probes) {
  Knob k;
  k.kind = kind;
  k.index = index;
  k.name = std::move(name);
  k.family = std::move(family);
  k.unit = std::move(unit);
  k.nominal = nominal;
  k.lo = lo;
  k.hi = hi;
  k.probes = std::move(probes);
  return k;
}

std::string RobotMjcfText(const SimConfig& config) {
  if (config.mjcf_path.empty()) return kBuiltinRobotMjcf;
  std::ifstream in(config.mjcf_path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw MakeInputError(config.mjcf_path, "mjcf_path", "cannot read the robot MJCF");
  return text.str();
}

void AddFloorSolrefKnobs(const mjModel* m, int floor, std::vector<Knob>* knobs) {
  const double tc = m->geom_solref[mjNREF * floor + 0];
  const double dr = m->geom_solref[mjNREF * floor + 1];
  if (!(tc > 0)) return;  // the standard (time constant, damping ratio) form only
  knobs->push_back(MakeKnob(KnobKind::kFloorSolrefTime, -1, "floor.solref.timeconst", "contact", "s", tc,
                            std::max(2.5 * m->opt.timestep, 0.25 * tc), 8 * tc, {3 * tc}));
  knobs->push_back(MakeKnob(KnobKind::kFloorSolrefDamping, -1, "floor.solref.dampratio", "contact", "", dr, 0.1 * dr,
                            4 * dr, {0.3 * dr}));
}

void AddTrackerNoiseKnob(const SimConfig& config, std::vector<Knob>* knobs) {
  const auto& n = config.noise;
  if (n.tracker_position_sd_m > 0 || n.tracker_yaw_sd_rad > 0 || n.tracker_roll_sd_rad > 0 ||
      n.tracker_pitch_sd_rad > 0) {
    knobs->push_back(MakeKnob(KnobKind::kTrackerNoiseScale, -1, "tracker.noise_scale", "tracker_noise", "", 1.0,
                              0.5, 5.0, {2.0}));
  }
}

void AddGroundKnobs(const SimConfig& config, std::vector<Knob>* knobs) {
  if (!config.terrain) return;
  const TerrainDescription& t = *config.terrain;
  const auto add = [&](bool has, KnobKind kind, const char* name) {
    if (has) knobs->push_back(MakeKnob(kind, -1, name, "ground", "", 1.0, 0.0, 3.0, {0.5, 1.5}));
  };
  add(t.rough.rms_height_m > 0, KnobKind::kGroundRoughness, "terrain.rough.rms_scale");
  add(t.stones.height_m > 0 && t.stones.per_m2 > 0, KnobKind::kGroundStoneHeight, "terrain.stones.height_scale");
  add(t.steps.height_m > 0, KnobKind::kGroundStepHeight, "terrain.steps.height_scale");
}

void ApplyGroundKnob(const SimConfig& config, KnobKind kind, double factor, SimConfig* out) {
  if (!config.terrain || !out->terrain) throw MakeInputError("simulation config", "terrain", "no terrain to scale");
  switch (kind) {
    case KnobKind::kGroundRoughness: out->terrain->rough.rms_height_m = config.terrain->rough.rms_height_m * factor; break;
    case KnobKind::kGroundStoneHeight: out->terrain->stones.height_m = config.terrain->stones.height_m * factor; break;
    case KnobKind::kGroundStepHeight: out->terrain->steps.height_m = config.terrain->steps.height_m * factor; break;
    default: break;
  }
}

void ScaleTrackerNoise(const SimConfig& config, double factor, SimConfig* out) {
  const auto& n = config.noise;
  out->noise.tracker_position_sd_m = n.tracker_position_sd_m * factor;
  out->noise.tracker_yaw_sd_rad = n.tracker_yaw_sd_rad * factor;
  out->noise.tracker_roll_sd_rad = n.tracker_roll_sd_rad * factor;
  out->noise.tracker_pitch_sd_rad = n.tracker_pitch_sd_rad * factor;
}

double PayloadProbeMass(const SimConfig& config) {
  if (config.robot) return 0.15 * Simulator(config).total_mass_kg();
  const auto& m = config.masses;
  return 0.15 * (m.torso_kg + kNumLegs * (m.coxa_kg + m.femur_kg + m.tibia_kg));
}

namespace {

// The torso child subtree carrying leg `leg`'s first actuator (-1: none), and the side rule
// shared by the knobs and their application: left (0) when that root sits at y > 0, else right (1).
int LegRoot(const mjModel* m, const RobotParts& parts, int leg) {
  const int joint = m->actuator_trnid[2 * parts.actuator[leg][0]];
  return TorsoChildOf(m, m->jnt_bodyid[joint], parts.torso_body);
}
int SideOf(const mjModel* m, int root) { return root >= 0 && m->body_pos[3 * root + 1] > 0 ? 0 : 1; }

void AddFrictionKnobs(const mjModel* m, const SimConfig& config, std::vector<Knob>* knobs) {
  const double mu = config.friction.sliding;
  knobs->push_back(MakeKnob(KnobKind::kFrictionSliding, -1, "floor.friction.sliding", "friction", "",
                            mu, 0.2 * mu, 2.0 * mu, {0.6 * mu, 1.5 * mu}));
  // Torsional friction acts only in contacts of condim >= 4 (a contact takes its geoms' condim, or
  // an explicit <pair>'s): with every geom and pair at 3 or less no contact uses it, and its probe
  // would be inert.
  int max_condim = 0;
  for (int g = 0; g < m->ngeom; ++g) max_condim = std::max(max_condim, m->geom_condim[g]);
  for (int p = 0; p < m->npair; ++p) max_condim = std::max(max_condim, m->pair_dim[p]);
  if (max_condim >= 4) {
    const double tor = config.friction.torsional;
    knobs->push_back(MakeKnob(KnobKind::kFrictionTorsional, -1, "floor.friction.torsional", "friction", "m", tor,
                              0.0, 20 * tor, {5 * tor}));
  }
}

void AddFloorContactKnobs(const mjModel* m, int floor, std::vector<Knob>* knobs) {
  AddFloorSolrefKnobs(m, floor, knobs);
  // solimp (dmin, dmax, width, midpoint, power); ranges widened to hold an unusual nominal.
  const double dmax = m->geom_solimp[mjNIMP * floor + 1];
  const double width = m->geom_solimp[mjNIMP * floor + 2];
  const double dmax_probe = std::abs(dmax - 0.7) > 0.05 ? 0.7 : 0.9;
  knobs->push_back(MakeKnob(KnobKind::kFloorSolimpDmax, -1, "floor.solimp.dmax", "contact", "", dmax,
                            std::min(0.5, dmax), std::max(0.99, dmax), {dmax_probe}));
  const double width_hi = std::max(0.02, width);
  const double width_probe = width < 0.01 ? 0.01 : 2 * width <= width_hi ? 2 * width : 0.5 * width;
  knobs->push_back(MakeKnob(KnobKind::kFloorSolimpWidth, -1, "floor.solimp.width", "contact", "m", width,
                            std::min(0.0002, width), width_hi, {width_probe}));
}

void AddPayloadKnobs(const mjModel* m, const RobotParts& parts, const SimConfig& config, std::vector<Knob>* knobs) {
  const double m0 = PayloadProbeMass(config);
  knobs->push_back(MakeKnob(KnobKind::kPayloadMass, -1, "payload.mass_kg", "payload", "kg",
                            config.payload.mass_kg, 0.0, 4 * m0, {config.payload.mass_kg + m0}));
  // Offsets relative to the robot's size: the leg roots' largest |x| and |y| in the torso frame
  // (the built-in robot's 0.225 and 0.15 m give probes of 0.1 m and a range of +-0.3 m).
  const Eigen::Vector2d span = LegRootSpan(m, parts);
  knobs->push_back(MakeKnob(KnobKind::kPayloadX, -1, "payload.position_x_m", "payload", "m",
                            config.payload.position_body_m.x(), -4.0 / 3 * span.x(), 4.0 / 3 * span.x(),
                            {4.0 / 9 * span.x()}));
  knobs->push_back(MakeKnob(KnobKind::kPayloadY, -1, "payload.position_y_m", "payload", "m",
                            config.payload.position_body_m.y(), -2 * span.y(), 2 * span.y(), {2.0 / 3 * span.y()}));
}

// Per leg a gain knob, then one per side with the legs of that side as members.
void AddLegKnobs(const mjModel* m, const RobotParts& parts, const SimConfig& config, std::vector<Knob>* knobs) {
  std::vector<std::string> side_members[2];
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const int root = LegRoot(m, parts, leg);
    if (root < 0) continue;
    const double g = config.actuators.leg_gain[leg];
    knobs->push_back(MakeKnob(KnobKind::kLegGain, leg, "actuators.leg" + std::to_string(leg) + ".gain",
                              "actuator_gain", "", g, 0.05 * g, 1.5 * g, {0.5 * g}));
    knobs->back().leg = "leg" + std::to_string(leg);
    side_members[SideOf(m, root)].push_back(knobs->back().leg);
  }
  const char* side_name[2] = {"left", "right"};
  for (int s = 0; s < 2; ++s) {
    if (side_members[s].empty()) continue;
    knobs->push_back(MakeKnob(KnobKind::kSideGain, s, std::string("actuators.") + side_name[s] + "_side.gain",
                              "actuator_gain", "", 1.0, 0.05, 1.5, {0.6}));
    knobs->back().members = side_members[s];
  }
}

void AddServoKnobs(const SimConfig& config, std::vector<Knob>* knobs) {
  knobs->push_back(MakeKnob(KnobKind::kKpScale, -1, "actuators.kp_scale", "actuator_gain", "", 1.0, 0.2, 2.5,
                            {0.6, 1.5}));
  knobs->push_back(MakeKnob(KnobKind::kDampingScale, -1, "joints.damping_scale", "joint_damping", "", 1.0,
                            0.05, 10.0, {0.25, 4.0}));
  const double lat = config.actuators.latency_s;
  knobs->push_back(MakeKnob(KnobKind::kLatency, -1, "actuators.latency_s", "latency", "s", lat, 0.0, 0.2,
                            {lat + 0.04}));
  const double bl = config.actuators.backlash_rad;
  knobs->push_back(MakeKnob(KnobKind::kBacklash, -1, "actuators.backlash_rad", "backlash", "rad", bl, 0.0, 0.2,
                            {bl + 0.03 <= 0.2 ? bl + 0.03 : bl - 0.03}));
}

}  // namespace

std::vector<Knob> EnumerateKnobs(const SimConfig& config) {
  if (config.robot) return EnumerateRobotKnobs(config);
  const std::string source = config.mjcf_path.empty() ? "built-in robot" : config.mjcf_path;
  MjModelPtr model = LoadRobotModel(config);
  const RobotParts parts = FindRobotParts(model.get(), config, source);
  ApplyConfig(config, parts, model.get(), source);
  const mjModel* m = model.get();
  std::vector<Knob> knobs;
  AddFrictionKnobs(m, config, &knobs);
  if (parts.floor_geom >= 0) AddFloorContactKnobs(m, parts.floor_geom, &knobs);
  knobs.push_back(MakeKnob(KnobKind::kMassScale, -1, "bodies.mass_scale", "mass", "", 1.0, 0.4, 2.5, {0.7, 1.4}));
  if (mj_name2id(m, mjOBJ_BODY, "payload") >= 0) AddPayloadKnobs(m, parts, config, &knobs);
  AddLegKnobs(m, parts, config, &knobs);
  AddServoKnobs(config, &knobs);
  // Last: a measurement-side knob of the simulator (the tracker's noise), config-level.
  AddGroundKnobs(config, &knobs);
  AddTrackerNoiseKnob(config, &knobs);
  return knobs;
}

namespace {

// The side of each leg by the rule of the knobs (SideOf).
std::array<int, kNumLegs> LegSides(const SimConfig& config) {
  const std::string source = config.mjcf_path.empty() ? "built-in robot" : config.mjcf_path;
  MjModelPtr model = LoadRobotModel(config);
  const RobotParts parts = FindRobotParts(model.get(), config, source);
  std::array<int, kNumLegs> side{};
  for (int leg = 0; leg < kNumLegs; ++leg) side[leg] = SideOf(model.get(), LegRoot(model.get(), parts, leg));
  return side;
}

// What the knobs change in the compiled model (nothing: an empty edit): every body's mass and
// inertia scaled, the floor's solref and solimp (dmin kept at most dmax).
struct FloorAndMassEdit {
  double mass_scale = 1;
  double solref_time = NAN, solref_damp = NAN, solimp_dmax = NAN, solimp_width = NAN;
  bool Any() const {
    return mass_scale != 1 || std::isfinite(solref_time) || std::isfinite(solref_damp) ||
           std::isfinite(solimp_dmax) || std::isfinite(solimp_width);
  }
  ModelEdit Make(const std::string& floor) const {
    if (!Any()) return {};
    const FloorAndMassEdit e = *this;
    return [e, floor](mjModel_* m) {
      if (e.mass_scale != 1) {
        for (int b = 1; b < m->nbody; ++b) {
          m->body_mass[b] *= e.mass_scale;
          for (int j = 0; j < 3; ++j) m->body_inertia[3 * b + j] *= e.mass_scale;
        }
      }
      const int g = mj_name2id(m, mjOBJ_GEOM, floor.c_str());
      if (g < 0) return;
      if (std::isfinite(e.solref_time)) m->geom_solref[mjNREF * g + 0] = e.solref_time;
      if (std::isfinite(e.solref_damp)) m->geom_solref[mjNREF * g + 1] = e.solref_damp;
      if (std::isfinite(e.solimp_dmax)) {
        m->geom_solimp[mjNIMP * g + 1] = e.solimp_dmax;
        m->geom_solimp[mjNIMP * g + 0] = std::min(m->geom_solimp[mjNIMP * g + 0], e.solimp_dmax);
      }
      if (std::isfinite(e.solimp_width)) m->geom_solimp[mjNIMP * g + 2] = e.solimp_width;
    };
  }
};

}  // namespace

SimConfig ApplyKnobs(const SimConfig& config, const std::vector<Knob>& knobs,
                     const std::vector<KnobValue>& values, ModelEdit* edit) {
  if (config.robot) return ApplyRobotKnobs(config, knobs, values, edit);
  SimConfig c = config;
  FloorAndMassEdit model;
  double damping_scale = 1;
  bool payload = false;
  double payload_mass = NAN;
  Eigen::Vector3d payload_pos = config.payload.position_body_m;
  bool need_sides = false;
  for (const auto& v : values) need_sides |= knobs.at(v.knob).kind == KnobKind::kSideGain;
  const std::array<int, kNumLegs> side = need_sides ? LegSides(config) : std::array<int, kNumLegs>{};
  for (const auto& v : values) {
    const Knob& k = knobs.at(v.knob);
    switch (k.kind) {
      case KnobKind::kFrictionSliding: c.friction.sliding = v.value; break;
      case KnobKind::kFrictionTorsional: c.friction.torsional = v.value; break;
      case KnobKind::kFloorSolrefTime: model.solref_time = v.value; break;
      case KnobKind::kFloorSolrefDamping: model.solref_damp = v.value; break;
      case KnobKind::kMassScale: model.mass_scale = v.value; break;
      case KnobKind::kPayloadMass: payload = true; payload_mass = v.value; break;
      case KnobKind::kPayloadX: payload = true; payload_pos.x() = v.value; break;
      case KnobKind::kPayloadY: payload = true; payload_pos.y() = v.value; break;
      case KnobKind::kLegGain: c.actuators.leg_gain[k.index] = v.value; break;
      case KnobKind::kSideGain:
        for (int leg = 0; leg < kNumLegs; ++leg) {
          if (side[leg] == k.index) c.actuators.leg_gain[leg] = config.actuators.leg_gain[leg] * v.value;
        }
        break;
      case KnobKind::kKpScale: c.actuators.kp_nm_per_rad = config.actuators.kp_nm_per_rad * v.value; break;
      case KnobKind::kDampingScale: damping_scale = v.value; break;
      case KnobKind::kFloorSolimpDmax: model.solimp_dmax = v.value; break;
      case KnobKind::kFloorSolimpWidth: model.solimp_width = v.value; break;
      case KnobKind::kLatency: c.actuators.latency_s = v.value; break;
      case KnobKind::kBacklash: c.actuators.backlash_rad = v.value; break;
      case KnobKind::kFrictionScale: break;  // a robot block's knob only
      case KnobKind::kTrackerNoiseScale: ScaleTrackerNoise(config, v.value, &c); break;
      case KnobKind::kGroundRoughness:
      case KnobKind::kGroundStoneHeight:
      case KnobKind::kGroundStepHeight: ApplyGroundKnob(config, k.kind, v.value, &c); break;
    }
  }
  if (payload) {
    c.payload.mass_kg = std::isfinite(payload_mass) ? payload_mass
                                                    : std::max(config.payload.mass_kg, PayloadProbeMass(config));
    c.payload.position_body_m = payload_pos;
  }
  c.actuators.joint_damping_nms_per_rad = config.actuators.joint_damping_nms_per_rad * damping_scale;
  if (edit) *edit = model.Make(config.names.floor_geom);
  return c;
}

SampleSet SimulateWithKnobs(const SimConfig& config, const ProtocolOptions& options,
                            const std::vector<Knob>& knobs, const std::vector<KnobValue>& values) {
  ModelEdit edit;
  const SimConfig c = ApplyKnobs(config, knobs, values, &edit);
  return SimulateProtocol(c, options, {}, nullptr, edit);
}

}  // namespace dgmm::sim
