#include "sim/robot_draft.h"

#include <mujoco/mujoco.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "sim/contact_extent.h"
#include "sim/legged_robot.h"
#include "sim/mujoco_model.h"
#include "sim/stance_load.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

// A jointed branch below the torso and its lowest point that can touch the floor.
struct Branch {
  int root = -1;        // the branch's first body with a joint
  int foot_geom = -1;   // its lowest geom that can touch the floor (-1: none)
  double low_z = 0;     // that geom's lowest point, m, torso at the origin
};

std::string Name(const mjModel* m, mjtObj type, int id) {
  const char* name = mj_id2name(m, type, id);
  return name ? name : "";
}

int FindTorso(const mjModel* m, const std::string& source) {
  std::vector<int> free;
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] == mjJNT_FREE) free.push_back(m->jnt_bodyid[j]);
  }
  if (free.size() != 1) {
    throw MakeInputError(source, "worldbody",
                         "one body with a free joint (the torso) expected, found " + std::to_string(free.size()));
  }
  if (Name(m, mjOBJ_BODY, free[0]).empty()) {
    throw MakeInputError(source, "worldbody", "the body with the free joint (the torso) needs a name");
  }
  return free[0];
}

int FindFloor(const mjModel* m, const std::string& source, std::vector<std::string>* notes) {
  std::vector<int> planes;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] == 0 && m->geom_type[g] == mjGEOM_PLANE && !Name(m, mjOBJ_GEOM, g).empty()) {
      planes.push_back(g);
    }
  }
  if (planes.empty()) {
    throw MakeInputError(source, "worldbody", "no named plane geom on the world body (the floor) found");
  }
  if (planes.size() > 1) {
    notes->push_back("floor: several named planes; the first, \"" + Name(m, mjOBJ_GEOM, planes[0]) +
                     "\", taken (robot.floor_geom)");
  }
  return planes[0];
}

// The first jointed bodies below `parent` in model order (bodies between them and `parent` have no
// joint: welded parts are looked through), each with its lowest geom that can touch the floor.
std::vector<Branch> BranchesBelow(const mjModel* m, const mjData* d, int parent, int floor) {
  std::vector<Branch> branches;
  for (int b = parent + 1; b < m->nbody; ++b) {
    if (!IsDescendant(m, b, parent) || m->body_jntnum[b] == 0) continue;
    bool first = true;
    for (int a = m->body_parentid[b]; a != parent; a = m->body_parentid[a]) first = first && m->body_jntnum[a] == 0;
    if (!first) continue;
    Branch branch{b};
    for (int g = 0; g < m->ngeom; ++g) {
      const int gb = m->geom_bodyid[g];
      if (!IsDescendant(m, gb, b) || !CanTouch(m, g, floor)) continue;
      const double low = d->geom_xpos[3 * g + 2] - ExtentBelow(m, d, g);
      if (branch.foot_geom < 0 || low < branch.low_z) branch = {b, g, low};
    }
    branches.push_back(branch);
  }
  return branches;
}

// Where the branches below the torso reach the ground, and which are body segments.
struct Branches {
  std::vector<Branch> legs_or_not;  // each a leg candidate (or a tail, a head: NotALeg)
  std::vector<int> segments;        // bodies carrying legs on both sides (behind a spine joint)
};

// A branch whose own branches put feet (within the foot band of the lowest point, `foot_z`) on
// both sides of the forward axis is a body segment, as no leg stands on both sides: its legs are
// the branches below it (recursively), its own joints the body's.
void CollectBranches(const mjModel* m, const mjData* d, int parent, int floor, const Eigen::Matrix3d& frame,
                     double foot_z, Branches* out) {
  for (const Branch& b : BranchesBelow(m, d, parent, floor)) {
    std::set<int> sides;
    for (const Branch& sub : BranchesBelow(m, d, b.root, floor)) {
      if (sub.foot_geom < 0 || sub.low_z > foot_z) continue;
      const mjtNum* p = d->geom_xpos + 3 * sub.foot_geom;
      sides.insert(FootSide(frame, Eigen::Vector3d(p[0], p[1], p[2])));
    }
    if (sides.size() < 2) {
      out->legs_or_not.push_back(b);
      continue;
    }
    out->segments.push_back(b.root);
    CollectBranches(m, d, b.root, floor, frame, foot_z, out);
  }
}

// A joint of no leg listed as held when driven, passive when not; true when driven.
bool ListHeldOrPassive(const mjModel* m, int j, const std::string& name, RobotDescription* r) {
  const bool driven = ActuatorOf(m, j) >= 0;
  (driven ? r->held_joints : r->passive_joints).push_back(name);
  return driven;
}

// A body segment's own joints: held when driven, passive when not (a note says which).
void SegmentJoints(const mjModel* m, int body, RobotDescription* r, std::vector<std::string>* notes) {
  std::string held, passive;
  for (int j = m->body_jntadr[body]; j < m->body_jntadr[body] + m->body_jntnum[body]; ++j) {
    const std::string name = Name(m, mjOBJ_JOINT, j);
    if (name.empty()) {
      notes->push_back("body segment \"" + Name(m, mjOBJ_BODY, body) + "\": joint " + std::to_string(j) +
                       " has no name: name it to list it");
      continue;
    }
    std::string& list = ListHeldOrPassive(m, j, name, r) ? held : passive;
    list += list.empty() ? name : ", " + name;
  }
  notes->push_back("body \"" + Name(m, mjOBJ_BODY, body) + "\" carries legs on both sides: a body segment, its legs "
                   "drafted below it" + (held.empty() ? "" : "; held at rest (driven): " + held) +
                   (passive.empty() ? "" : "; passive: " + passive));
}

// The common prefix of the leg's joint names without trailing separators ("FR" of FR_hip_joint,
// FR_thigh_joint, FR_calf_joint); the first body's name when there is none.
std::string LegName(const std::vector<std::string>& joints, const std::string& body) {
  std::string prefix = joints.size() >= 2 ? joints[0] : "";
  for (const auto& j : joints) {
    std::size_t n = 0;
    while (n < prefix.size() && n < j.size() && prefix[n] == j[n]) ++n;
    prefix.resize(n);
  }
  while (!prefix.empty() && std::string("_-. :/").find(prefix.back()) != std::string::npos) prefix.pop_back();
  return prefix.empty() ? body : prefix;
}

// The leg of a branch: driven hinge and slide joints from the torso to the foot geom's body; the
// undriven ones go to `passive`. Nothing (and a note) when the branch cannot be described; the
// name may be empty (MakeNamesUnique gives it one).
std::optional<LegDescription> DescribeLeg(const mjModel* m, const Branch& branch, std::vector<std::string>* passive,
                                          std::vector<std::string>* notes) {
  LegDescription leg;
  std::vector<std::string> undriven;
  const std::string root = Name(m, mjOBJ_BODY, branch.root);
  std::vector<int> path;
  for (int b = m->geom_bodyid[branch.foot_geom]; b != m->body_parentid[branch.root]; b = m->body_parentid[b]) {
    path.insert(path.begin(), b);
  }
  for (int b : path) {
    for (int j = m->body_jntadr[b]; j < m->body_jntadr[b] + m->body_jntnum[b]; ++j) {
      const std::string name = Name(m, mjOBJ_JOINT, j);
      if (name.empty() || (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE)) {
        notes->push_back("branch at body \"" + root + "\": joint " + std::to_string(j) +
                         (name.empty() ? " has no name" : " (\"" + name + "\") is neither hinge nor slide") +
                         ", so the branch is not drafted as a leg");
        return std::nullopt;
      }
      (ActuatorOf(m, j) >= 0 ? leg.joints : undriven).push_back(name);
    }
  }
  leg.name = LegName(leg.joints, root);
  const std::string geom = Name(m, mjOBJ_GEOM, branch.foot_geom);
  const int body = m->geom_bodyid[branch.foot_geom];
  if (!geom.empty()) {
    leg.foot.geom = geom;
  } else if (!Name(m, mjOBJ_BODY, body).empty()) {
    leg.foot.body = Name(m, mjOBJ_BODY, body);
    const mjtNum* p = m->geom_pos + 3 * branch.foot_geom;
    leg.foot.offset_m = Eigen::Vector3d(p[0], p[1], p[2]);
  } else {
    notes->push_back("branch at body \"" + root + "\": its lowest geom and that geom's body have no name, so the "
                     "branch is not drafted as a leg");
    return std::nullopt;
  }
  passive->insert(passive->end(), undriven.begin(), undriven.end());
  return leg;
}

// A branch that is not a leg (a tail, a head): its named joints are held when driven, passive
// when not (a note says so).
void NotALeg(const mjModel* m, const Branch& branch, RobotDescription* r, std::vector<std::string>* notes) {
  const std::string root = Name(m, mjOBJ_BODY, branch.root);
  bool held = false;
  for (int j = 0; j < m->njnt; ++j) {
    const std::string name = Name(m, mjOBJ_JOINT, j);
    if (!IsDescendant(m, m->jnt_bodyid[j], branch.root) || name.empty()) continue;
    held = ListHeldOrPassive(m, j, name, r) || held;
  }
  notes->push_back("branch at body \"" + (root.empty() ? std::to_string(branch.root) : root) +
                   "\" does not reach the ground at rest: not a leg, its joints " +
                   (held ? "held at rest where driven, passive where not" : "passive"));
}

// Joints of a branch off its foot chain: undriven ones are passive; driven ones are noted.
void OffChainJoints(const mjModel* m, const Branch& branch, const LegDescription& leg, std::vector<std::string>* passive,
                    std::vector<std::string>* notes) {
  std::set<std::string> on(leg.joints.begin(), leg.joints.end());
  on.insert(passive->begin(), passive->end());
  for (int j = 0; j < m->njnt; ++j) {
    const std::string name = Name(m, mjOBJ_JOINT, j);
    if (!IsDescendant(m, m->jnt_bodyid[j], branch.root) || on.count(name)) continue;
    if (name.empty()) {
      notes->push_back("joint " + std::to_string(j) + " below leg " + leg.name + " has no name: name it to list it");
    } else if (ActuatorOf(m, j) < 0) {
      passive->push_back(name);
    } else {
      notes->push_back("joint \"" + name + "\" is driven but off the way from the torso to the foot of leg " + leg.name +
                       ": add it to a leg's joints or its actuator will be refused");
    }
  }
}

// Unique leg names: a repeated one gets its leg's index.
void MakeNamesUnique(std::vector<LegDescription>* legs) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < legs->size(); ++i) {
    auto& name = (*legs)[i].name;
    if (name.empty() || !seen.insert(name).second) seen.insert(name = "leg" + std::to_string(i));
  }
}

// Each leg's side from the geometry: the foot's side of the forward axis at rest (the rule the
// binding uses).
void Sides(const mjData* d, const RobotDraftOptions& o, const std::vector<Branch>& legs, RobotDescription* robot) {
  const Eigen::Matrix3d frame = RobotFrame(o.forward_axis);
  for (std::size_t i = 0; i < legs.size(); ++i) {
    const mjtNum* p = d->geom_xpos + 3 * legs[i].foot_geom;
    robot->legs[i].side = FootSide(frame, Eigen::Vector3d(p[0], p[1], p[2])) > 0 ? "left" : "right";
  }
}

// A note when the torso is clearly longer along another horizontal direction than the forward
// axis: its mass's second moments E[r r^T] = tr(I)/2 - I from its inertia in the torso frame.
void ForwardAxisNote(const mjModel* m, int torso, const RobotDraftOptions& o, std::vector<std::string>* notes) {
  const mjtNum* q = m->body_iquat + 4 * torso;
  const Eigen::Matrix3d r = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  const Eigen::Vector3d diag(m->body_inertia[3 * torso], m->body_inertia[3 * torso + 1], m->body_inertia[3 * torso + 2]);
  const Eigen::Matrix3d inertia = r * diag.asDiagonal() * r.transpose();
  const Eigen::Matrix3d moments = 0.5 * inertia.trace() * Eigen::Matrix3d::Identity() - inertia;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(moments.topLeftCorner<2, 2>());
  const Eigen::Vector2d lengths = horizontal.eigenvalues().cwiseMax(0).cwiseSqrt();
  Eigen::Vector2d along = horizontal.eigenvectors().col(1);
  if (along.cwiseAbs().maxCoeff() != along.maxCoeff()) along = -along;  // its largest component positive
  const Eigen::Vector2d forward = o.forward_axis.head<2>().normalized();
  if (lengths[1] > 1.3 * lengths[0] && std::abs(along.dot(forward)) < std::cos(M_PI / 6)) {
    char axis[64];
    std::snprintf(axis, sizeof(axis), "%.2g,%.2g,0", along.x(), along.y());
    notes->push_back(std::string("forward axis: the torso is longest along ") + axis +
                     "; if the robot walks that way, give --forward-axis " + axis);
  }
}

// Servos that give under the robot's weight (stance_load.h) get the gait's feedforward, unless a
// leg carries passive joints, whose give the feedforward cannot take out.
void FeedforwardIfTheServosGive(const mjModel* m, const LeggedRobot& bound, RobotDescription* r,
                                std::vector<std::string>* notes) {
  const StanceLoad load = MeasureStanceLoad(m, bound);
  if (!ServosGive(load, bound)) return;
  const bool passive = LegsHavePassiveJoints(m, bound);
  char what[300];
  std::snprintf(what, sizeof what, "gait: leg %s's foot gives %.3g m (%.0f%% of the stride) under its share of the weight",
                bound.legs[load.sag_leg].name.c_str(), load.sag_m, 100 * load.sag_m / bound.stride_m);
  r->gait.servo_feedforward = !passive;
  notes->push_back(std::string(what) + (passive ? "; the legs' passive joints give too, which the servo feedforward "
                                                   "does not take out: left off (robot.gait.servo_feedforward)"
                                                 : ": servo_feedforward on (targets that carry the weight)"));
}

}  // namespace

bool RobotDraftOptions::IsValid(std::string* error) const {
  if (!(forward_axis.allFinite() && std::hypot(forward_axis.x(), forward_axis.y()) > 1e-9)) {
    *error = "forward_axis: a direction with a horizontal part expected";
    return false;
  }
  if (!(foot_band > 0 && foot_band < 1)) {
    *error = "foot_band: in (0, 1) expected";
    return false;
  }
  return true;
}

RobotDraft DraftRobot(const std::string& mjcf_path, const RobotDraftOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError(mjcf_path, "options", error);
  SimConfig config;
  config.mjcf_path = mjcf_path;
  const MjModelPtr model = LoadRobotModel(config);
  const mjModel* m = model.get();
  RobotDraft draft;
  RobotDescription& r = draft.robot;
  draft.timestep_s = m->opt.timestep;
  const int torso = FindTorso(m, mjcf_path), floor = FindFloor(m, mjcf_path, &draft.notes);
  r.torso_body = Name(m, mjOBJ_BODY, torso), r.floor_geom = Name(m, mjOBJ_GEOM, floor);
  r.forward_axis = options.forward_axis;
  const MjDataPtr d = RestPoseData(m, m->jnt_qposadr[m->body_jntadr[torso]]);
  mj_kinematics(m, d.get());
  double lowest = 0;
  for (const auto& b : BranchesBelow(m, d.get(), torso, floor)) {
    if (b.foot_geom >= 0) lowest = std::min(lowest, b.low_z);
  }
  if (!(lowest < 0)) throw MakeInputError(mjcf_path, "worldbody", "no jointed branch below the torso reaches the ground");
  Branches branches;
  const double foot_z = (1 - options.foot_band) * lowest;
  CollectBranches(m, d.get(), torso, floor, RobotFrame(options.forward_axis), foot_z, &branches);
  for (int body : branches.segments) SegmentJoints(m, body, &r, &draft.notes);
  std::vector<Branch> legs;
  for (const auto& b : branches.legs_or_not) {
    if (b.foot_geom < 0 || b.low_z > foot_z) {
      NotALeg(m, b, &r, &draft.notes);
      continue;
    }
    const std::optional<LegDescription> leg = DescribeLeg(m, b, &r.passive_joints, &draft.notes);
    if (!leg) continue;
    OffChainJoints(m, b, *leg, &r.passive_joints, &draft.notes);
    r.legs.push_back(*leg), legs.push_back(b);
  }
  MakeNamesUnique(&r.legs);
  Sides(d.get(), options, legs, &r);
  ForwardAxisNote(m, torso, options, &draft.notes);
  try {
    FeedforwardIfTheServosGive(m, BindRobot(m, r, mjcf_path), &r, &draft.notes);
  } catch (const InputError& e) {
    draft.bind_error = e.what();
  }
  return draft;
}

}  // namespace dgmm::sim
