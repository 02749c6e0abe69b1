#include "sim/mujoco_model.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>

#include "sim/compiled_model.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

constexpr const char* kJointNames[3] = {"hip_yaw", "hip_pitch", "knee"};
constexpr const char* kSegmentNames[3] = {"coxa", "femur", "tibia"};

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

Eigen::Vector3d Vec(const mjtNum* v) { return {v[0], v[1], v[2]}; }
Eigen::Matrix3d Mat(const mjtNum* m) {
  return Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(m);
}

std::string LegName(const SimConfig& c, int leg, const char* part) {
  return c.names.actuator_prefix + std::to_string(leg) + "_" + part;
}

int RequireId(const mjModel* m, mjtObj type, const std::string& name, const char* what,
              const std::string& source) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) throw MakeInputError(source, name, std::string("no ") + what + " of that name");
  return id;
}

void SetBodyMass(mjModel* m, int body, double mass_kg) {
  const double old = m->body_mass[body];
  if (old > 0) {
    for (int k = 0; k < 3; ++k) m->body_inertia[3 * body + k] *= mass_kg / old;
  }
  m->body_mass[body] = mass_kg;
}

// MuJoCo's compile error on one line (its XML errors span several: "XML parse error 3:\nError=...").
std::string OneLine(const char* error) {
  std::string line = error[0] ? error : "MuJoCo cannot load it";
  while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
  for (char& c : line) c = c == '\n' ? ' ' : c;
  return line;
}

}  // namespace

MjModelPtr LoadWithFiles(const std::vector<std::pair<std::string, std::string>>& files,
                         const std::string& load_path, const std::string& source_name) {
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  for (const auto& [name, text] : files) {
    if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(text.size())) != 0) {
      throw MakeInputError(source_name, "", "cannot stage the MJCF in memory");
    }
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name.c_str())], text.data(), text.size());
  }
  char error[1000] = "";
  MjModelPtr model(mj_loadXML(load_path.c_str(), vfs.get(), error, sizeof(error)));
  if (!model) throw MakeInputError(source_name, "MJCF", OneLine(error));
  return model;
}

MjModelPtr LoadMjcfString(const std::string& xml, const std::string& source_name) {
  return LoadWithFiles({{"robot.xml", xml}}, "robot.xml", source_name);
}

MjModelPtr LoadRobotModel(const SimConfig& config) {
  if (config.mjcf_path.empty()) return LoadMjcfString(kBuiltinRobotMjcf, "built-in robot");
  char error[1000] = "";
  MjModelPtr model(mj_loadXML(config.mjcf_path.c_str(), nullptr, error, sizeof(error)));
  if (!model) throw MakeInputError(config.mjcf_path, "MJCF", OneLine(error));
  return model;
}

bool StepChecked(const mjModel* m, mjData* d) {
  mj_step(m, d);
  bool ok = true;
  for (int w = 0; w < mjNWARNING; ++w) {
    if (d->warning[w].number > 0) ok = false;
    d->warning[w].number = 0;
  }
  return ok;
}

std::string CompiledModelBytes(const SimConfig& config) {
  const MjModelPtr model = LoadRobotModel(config);
  std::string bytes(static_cast<std::size_t>(mj_sizeModel(model.get())), '\0');
  mj_saveModel(model.get(), nullptr, bytes.data(), static_cast<int>(bytes.size()));
  return bytes;
}

RobotParts FindRobotParts(const mjModel* m, const SimConfig& c, const std::string& source) {
  RobotParts parts;
  parts.torso_body = RequireId(m, mjOBJ_BODY, c.names.torso_body, "body", source);
  const int root_joint = m->body_jntadr[parts.torso_body];
  if (root_joint < 0 || m->jnt_type[root_joint] != mjJNT_FREE) {
    throw MakeInputError(source, c.names.torso_body, "the torso body needs a free joint");
  }
  parts.torso_qpos = m->jnt_qposadr[root_joint];
  parts.torso_dof = m->jnt_dofadr[root_joint];
  parts.floor_geom = RequireId(m, mjOBJ_GEOM, c.names.floor_geom, "geom", source);

  MjDataPtr d(mj_makeData(m));
  mj_kinematics(m, d.get());
  const Eigen::Vector3d torso_p = Vec(d->xpos + 3 * parts.torso_body);
  const Eigen::Matrix3d torso_r = Mat(d->xmat + 9 * parts.torso_body);
  auto in_torso = [&](const mjtNum* world) { return Eigen::Vector3d(torso_r.transpose() * (Vec(world) - torso_p)); };
  const double kTol = 2e-3;  // m (and cosine slack): conventions are checked to about a millimetre

  for (int leg = 0; leg < kNumLegs; ++leg) {
    Eigen::Vector3d anchor[3], axis[3];
    for (int j = 0; j < 3; ++j) {
      const std::string name = LegName(c, leg, kJointNames[j]);
      const int act = RequireId(m, mjOBJ_ACTUATOR, name, "actuator", source);
      const int joint = RequireId(m, mjOBJ_JOINT, name, "joint", source);
      if (m->jnt_type[joint] != mjJNT_HINGE || m->actuator_trntype[act] != mjTRN_JOINT ||
          m->actuator_trnid[2 * act] != joint) {
        throw MakeInputError(source, name, "expected a hinge joint driven by the actuator of the same name");
      }
      parts.actuator[leg][j] = act;
      parts.joint[leg][j] = joint;
      anchor[j] = in_torso(d->xanchor + 3 * joint);
      axis[j] = torso_r.transpose() * Vec(d->xaxis + 3 * joint);
    }
    const std::string foot_name = LegName(c, leg, "foot");
    const int foot_site = RequireId(m, mjOBJ_SITE, foot_name, "site", source);
    const Eigen::Vector3d foot = in_torso(d->site_xpos + 3 * foot_site);
    parts.foot_site[leg] = foot_site;

    LegGeometry g;
    g.hip_m = anchor[0];
    Eigen::Vector3d out = anchor[1] - anchor[0];
    out.z() = 0;
    if (out.norm() < 1e-6) out = Eigen::Vector3d(anchor[2].x() - anchor[0].x(), anchor[2].y() - anchor[0].y(), 0);
    out.normalize();
    g.outward_rad = std::atan2(out.y(), out.x());
    g.coxa_out_m = (anchor[1] - anchor[0]).dot(out);
    g.coxa_up_m = anchor[1].z() - anchor[0].z();
    const Eigen::Vector3d femur = anchor[2] - anchor[1];
    const Eigen::Vector3d tibia = foot - anchor[2];
    g.femur_m = femur.norm();
    g.tibia_m = -tibia.z();
    const Eigen::Vector3d pitch_axis = out.cross(Eigen::Vector3d::UnitZ());
    if (axis[0].dot(Eigen::Vector3d::UnitZ()) < 1 - kTol || axis[1].dot(pitch_axis) < 1 - kTol ||
        axis[2].dot(pitch_axis) < 1 - kTol) {
      throw MakeInputError(source, LegName(c, leg, "*"),
                           "joint axes must be: hip_yaw along torso +z, hip_pitch and knee along "
                           "outward x up (positive lifts the foot)");
    }
    if (std::abs(femur.z()) > kTol || femur.dot(out) < g.femur_m - kTol || g.femur_m < 0.01 ||
        g.tibia_m < 0.01 || std::hypot(tibia.x(), tibia.y()) > kTol) {
      throw MakeInputError(source, LegName(c, leg, "*"),
                           "at q = 0 the femur must point level outward and the tibia straight down "
                           "to the foot site");
    }
    const int foot_geom = mj_name2id(m, mjOBJ_GEOM, foot_name.c_str());
    g.foot_radius_m = foot_geom >= 0 && m->geom_type[foot_geom] == mjGEOM_SPHERE ? m->geom_size[3 * foot_geom] : 0;
    parts.legs[leg] = g;
  }
  return parts;
}

void ApplyConfig(const SimConfig& c, const RobotParts& parts, mjModel* m, const std::string& source) {
  m->opt.timestep = c.timestep_s;
  double g = std::sqrt(m->opt.gravity[0] * m->opt.gravity[0] + m->opt.gravity[1] * m->opt.gravity[1] +
                       m->opt.gravity[2] * m->opt.gravity[2]);
  if (g <= 0) g = 9.81;
  const double slope = c.slope_deg * M_PI / 180;
  m->opt.gravity[0] = -g * std::sin(slope);  // downhill is -x in the slope frame
  m->opt.gravity[1] = 0;
  m->opt.gravity[2] = -g * std::cos(slope);

  for (int i = 0; i < m->ngeom; ++i) {
    m->geom_friction[3 * i + 0] = c.friction.sliding;
    m->geom_friction[3 * i + 1] = c.friction.torsional;
    m->geom_friction[3 * i + 2] = c.friction.rolling;
  }

  SetBodyMass(m, parts.torso_body, c.masses.torso_kg);
  const double segment_kg[3] = {c.masses.coxa_kg, c.masses.femur_kg, c.masses.tibia_kg};
  for (int leg = 0; leg < kNumLegs; ++leg) {
    for (int s = 0; s < 3; ++s) {
      const int body = mj_name2id(m, mjOBJ_BODY, LegName(c, leg, kSegmentNames[s]).c_str());
      if (body >= 0) SetBodyMass(m, body, segment_kg[s]);
    }
  }
  const int payload = mj_name2id(m, mjOBJ_BODY, "payload");
  if (payload < 0 && c.payload.mass_kg > 0) {
    throw MakeInputError(source, "payload", "the model has no body named \"payload\" to carry it");
  }
  if (payload >= 0) {
    const double mass = std::max(c.payload.mass_kg, 1e-6);
    const double kRadius = 0.03;  // m: a compact block
    m->body_mass[payload] = mass;
    for (int k = 0; k < 3; ++k) {
      m->body_inertia[3 * payload + k] = 0.4 * mass * kRadius * kRadius;
      m->body_pos[3 * payload + k] = c.payload.position_body_m[k];
      m->body_ipos[3 * payload + k] = 0;
    }
    for (int gi = 0; gi < m->ngeom; ++gi) {
      if (m->geom_bodyid[gi] != payload) continue;
      m->geom_rgba[4 * gi + 3] = c.payload.mass_kg > 0 ? 1.0f : 0.0f;
      for (int k = 0; k < 3; ++k) m->geom_pos[3 * gi + k] = 0;
    }
  }

  for (int leg = 0; leg < kNumLegs; ++leg) {
    const double kp = c.actuators.kp_nm_per_rad * c.actuators.leg_gain[leg];
    for (int j = 0; j < 3; ++j) {
      const int a = parts.actuator[leg][j];
      m->actuator_gaintype[a] = mjGAIN_FIXED;
      m->actuator_biastype[a] = mjBIAS_AFFINE;
      m->actuator_gainprm[mjNGAIN * a + 0] = kp;
      m->actuator_biasprm[mjNBIAS * a + 0] = 0;
      m->actuator_biasprm[mjNBIAS * a + 1] = -kp;
      m->actuator_biasprm[mjNBIAS * a + 2] = 0;
      m->actuator_forcelimited[a] = 1;
      m->actuator_forcerange[2 * a + 0] = -c.actuators.torque_limit_nm;
      m->actuator_forcerange[2 * a + 1] = c.actuators.torque_limit_nm;
      m->dof_damping[m->jnt_dofadr[parts.joint[leg][j]]] = c.actuators.joint_damping_nms_per_rad;
    }
  }
}

}  // namespace dgmm::sim
