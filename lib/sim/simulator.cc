#include "sim/simulator.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sim/actuation_line.h"
#include "sim/gait_reach.h"
#include "sim/generic_walker.h"
#include "sim/ground.h"
#include "sim/mujoco_model.h"
#include "sim/stance_load.h"
#include "sim/walk_check.h"
#include "util/error.h"

namespace dgmm::sim {

struct Simulator::Impl {
  std::unique_ptr<Ground> ground;         // the floor plane or the config's height field
  std::unique_ptr<GenericWalker> walker;  // a robot block's robot; else the built-in conventions
  SimConfig config;
  MjModelPtr model;
  MjDataPtr data;
  SelfContacts self_contacts;
  RobotParts parts;
  Eigen::Vector3d up;
  double time_s = 0;

  // The leg servos' targets on their way (latency and backlash: sim/actuation_line.h), in
  // leg-major order (leg * 3 + joint).
  ActuationLine line;

  Eigen::VectorXd JointTargets(const std::array<Eigen::Vector3d, kNumLegs>& feet) const {
    Eigen::VectorXd q(3 * kNumLegs);
    for (int leg = 0; leg < kNumLegs; ++leg) {
      const LegAngles angles = LegInverse(parts.legs[leg], feet[leg]);
      for (int j = 0; j < 3; ++j) q[3 * leg + j] = angles[j];
    }
    return q;
  }
  // Sets the servo targets at once (no targets in flight).
  void ResetFootTargets(const std::array<Eigen::Vector3d, kNumLegs>& feet) {
    line.Reset(JointTargets(feet));
    line.Write(data.get());
  }
  // Sends the joint angles reaching the given foot targets; the servos see them after the
  // configured latency (at once when it is zero).
  void SetFootTargets(const std::array<Eigen::Vector3d, kNumLegs>& feet) {
    line.Send(JointTargets(feet));
    line.Write(data.get());
  }
  std::array<Eigen::Vector3d, kNumLegs> NominalFeet() const {
    std::array<Eigen::Vector3d, kNumLegs> feet;
    for (int leg = 0; leg < kNumLegs; ++leg) feet[leg] = NominalFoot(parts.legs[leg], config.gait);
    return feet;
  }
  Pose Torso() const {
    Pose pose;
    const int b = parts.torso_body;
    pose.position_m = Eigen::Vector3d(data->xpos[3 * b], data->xpos[3 * b + 1], data->xpos[3 * b + 2]);
    pose.rotation = Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(data->xmat + 9 * b);
    return pose;
  }
  // One physics step; false on a MuJoCo warning (bad numbers, full contact buffers).
  bool Step() {
    line.Write(data.get());  // the backlash dead band follows the joints step by step
    time_s += model->opt.timestep;
    const bool ok = StepChecked(model.get(), data.get());
    self_contacts.Observe(model.get(), data.get());
    return ok;
  }
  std::vector<Eigen::Vector3d> FootSites() const {
    std::vector<Eigen::Vector3d> feet;
    for (const int site : parts.foot_site) {
      const mjtNum* p = data->site_xpos + 3 * site;
      feet.emplace_back(p[0], p[1], p[2]);
    }
    return feet;
  }
  bool Fallen() const {
    const Pose pose = Torso();
    const double kMaxTiltCos = 0.5;      // 60 degrees from the slope normal
    const double kMinHeightShare = 0.4;  // of the stance height
    // From the mean ground under the feet: a stone under the belly is no fall.
    const double ground_m = ground->field() ? ground->MeanUnder(FootSites()) : 0.0;
    return pose.rotation(2, 2) < kMaxTiltCos ||
           pose.position_m.z() - ground_m < kMinHeightShare * config.gait.stance_height_m;
  }
  // Runs `steps` steps with targets from `feet_at(step)`; stops at a fall or instability.
  // `sample(s)` runs after every step.
  template <typename FeetAt, typename Sample>
  RunOutcome Run(int steps, FeetAt feet_at, Sample sample) {
    for (int s = 0; s < steps; ++s) {
      SetFootTargets(feet_at(s));
      if (!Step()) return RunOutcome::kUnstable;
      sample(s);
      if (Fallen()) return RunOutcome::kFell;
    }
    return RunOutcome::kCompleted;
  }
};

namespace {
// MuJoCo's default warning handler prints to stdout and appends to MUJOCO_LOG.TXT in the working
// directory. Warnings are read from mjData::warning instead (a step with one is kUnstable), so
// unless someone (e.g. a test fixture) installed a handler, they are silenced.
void QuietWarning(const char*) {}
}  // namespace

Simulator::Simulator(const SimConfig& config, const ModelEdit& edit) : impl_(std::make_unique<Impl>()) {
  if (mju_user_warning == nullptr) mju_user_warning = QuietWarning;
  std::string error;
  if (!config.IsValid(&error)) throw MakeInputError("simulation config", "", error);
  const std::string source = config.mjcf_path.empty() ? "built-in robot" : config.mjcf_path;
  impl_->config = config;
  impl_->ground = std::make_unique<Ground>(config);
  if (config.robot) {
    impl_->walker = std::make_unique<GenericWalker>(config, impl_->ground->Load(config), *impl_->ground, source);
    if (edit) edit(impl_->walker->model());
    impl_->ground->Install(impl_->walker->model(), impl_->walker->robot().floor_geom, source);
    impl_->walker->Start();
    const double a = config.slope_deg * M_PI / 180;
    impl_->up = Eigen::Vector3d(std::sin(a), 0, std::cos(a));
    return;
  }
  impl_->model = impl_->ground->Load(config);
  impl_->parts = FindRobotParts(impl_->model.get(), config, source);
  ApplyConfig(config, impl_->parts, impl_->model.get(), source);
  if (edit) edit(impl_->model.get());
  impl_->ground->Install(impl_->model.get(), impl_->parts.floor_geom, source);
  impl_->data.reset(mj_makeData(impl_->model.get()));
  const int latency_steps =
      static_cast<int>(std::lround(config.actuators.latency_s / config.timestep_s));
  std::vector<int> leg_servos;
  for (int leg = 0; leg < kNumLegs; ++leg) {
    for (int j = 0; j < 3; ++j) leg_servos.push_back(impl_->parts.actuator[leg][j]);
  }
  impl_->line = ActuationLine(impl_->model.get(), leg_servos, latency_steps, config.actuators.backlash_rad);
  mj_setConst(impl_->model.get(), impl_->data.get());
  const double a = config.slope_deg * M_PI / 180;
  impl_->up = Eigen::Vector3d(std::sin(a), 0, std::cos(a));
}

Simulator::~Simulator() = default;

RunOutcome Simulator::Place(double x_m, double y_m, double heading_rad) {
  if (impl_->walker) return impl_->walker->Place(x_m, y_m, heading_rad);
  Impl& s = *impl_;
  mjModel* m = s.model.get();
  mjData* d = s.data.get();
  mj_resetData(m, d);
  const auto feet = s.NominalFeet();
  for (int leg = 0; leg < kNumLegs; ++leg) {
    const LegAngles q = LegInverse(s.parts.legs[leg], feet[leg]);
    for (int j = 0; j < 3; ++j) d->qpos[m->jnt_qposadr[s.parts.joint[leg][j]]] = q[j];
  }
  const int q0 = s.parts.torso_qpos;
  const double kDropM = 0.005;  // released just above the ground under the highest foot
  std::vector<Eigen::Vector2d> stance;
  for (const auto& foot : feet) stance.push_back(foot.head<2>());
  const double ground_m = s.ground->HighestUnder(x_m, y_m, heading_rad, stance);
  d->qpos[q0 + 0] = x_m;
  d->qpos[q0 + 1] = y_m;
  d->qpos[q0 + 2] = ground_m + s.config.gait.stance_height_m + kDropM;
  d->qpos[q0 + 3] = std::cos(heading_rad / 2);
  d->qpos[q0 + 4] = 0;
  d->qpos[q0 + 5] = 0;
  d->qpos[q0 + 6] = std::sin(heading_rad / 2);
  s.ResetFootTargets(feet);
  mj_forward(m, d);
  return Stand(s.config.settle_duration_s);
}

RunOutcome Simulator::Stand(double seconds) {
  if (impl_->walker) return impl_->walker->Stand(seconds);
  Impl& s = *impl_;
  const auto feet = s.NominalFeet();
  const int steps = static_cast<int>(std::lround(seconds / s.model->opt.timestep));
  return s.Run(steps, [&](int) { return feet; }, [](int) {});
}

RunOutcome Simulator::RunCommand(const Eigen::Vector3d& command, std::vector<Pose>* trajectory,
                                 int sample_every) {
  return RunCommand(
      command,
      [trajectory](const Simulator& sim) {
        if (trajectory) trajectory->push_back(sim.TorsoPose());
      },
      sample_every);
}

RunOutcome Simulator::RunCommand(const Eigen::Vector3d& command,
                                 const std::function<void(const Simulator&)>& observer,
                                 int observe_every) {
  if (impl_->walker) {
    return impl_->walker->Run(command, [&](int step) {
      if (observer && (step + 1) % std::max(1, observe_every) == 0) observer(*this);
    });
  }
  Impl& s = *impl_;
  const double dt = s.model->opt.timestep;
  const double duration = s.config.command_duration_s;
  const int steps = static_cast<int>(std::lround(duration / dt));
  const Eigen::Vector3d c = command.cwiseMax(-1.0).cwiseMin(1.0);
  std::array<Eigen::Vector3d, kNumLegs> feet;
  return s.Run(
      steps,
      [&](int step) {
        const double t = (step + 1) * dt;
        for (int leg = 0; leg < kNumLegs; ++leg) {
          feet[leg] = FootTarget(s.parts.legs[leg], leg, c, t, duration, s.config.gait);
        }
        return feet;
      },
      [&](int step) {
        if (observer && (step + 1) % std::max(1, observe_every) == 0) observer(*this);
      });
}

Pose Simulator::TorsoPose() const { return impl_->walker ? impl_->walker->RobotPose() : impl_->Torso(); }

std::vector<Eigen::Vector3d> Simulator::FootPositions() const {
  return impl_->walker ? impl_->walker->FootPoints() : impl_->FootSites();
}

std::vector<std::string> Simulator::RobotWarnings() const {
  const SimConfig& c = impl_->config;
  std::vector<std::string> out;
  if (impl_->walker && impl_->walker->robot().replay.empty()) {
    const LeggedRobot& robot = impl_->walker->robot();
    out = GaitReachWarnings(MeasureGaitMisses(impl_->walker->model(), robot, c.robot->gait.turn_rad), robot);
  }
  const std::string tracker = TrackerNoiseWarning(c.noise.tracker_position_sd_m, CommandedWalkOf(c, leg_reach_m()));
  if (!tracker.empty()) out.push_back(tracker);
  if (impl_->walker) {
    const LeggedRobot& robot = impl_->walker->robot();
    const mjModel* m = impl_->walker->model();
    const std::vector<std::string> load =
        StanceLoadWarnings(MeasureStanceLoad(m, robot), m, robot, c.robot->gait.servo_feedforward);
    out.insert(out.end(), load.begin(), load.end());
  }
  if (!c.terrain) return out;
  double stance = c.gait.stance_height_m, foot = 0;
  if (impl_->walker) {
    stance = impl_->walker->robot().stance_height_m;
    for (const LegChain& leg : impl_->walker->robot().legs) foot = std::max(foot, leg.foot_extent_m);
  } else {
    for (const LegGeometry& leg : impl_->parts.legs) foot = std::max(foot, leg.foot_radius_m);
  }
  const std::vector<std::string> terrain = TerrainScaleWarnings(*c.terrain, stance, foot);
  out.insert(out.end(), terrain.begin(), terrain.end());
  const double half = placement_half_width_m(), reach = leg_reach_m();
  if (half + 2 * reach > c.terrain->half_size_m) {
    char what[200];
    std::snprintf(what, sizeof what,
                  "placements reach %.3g m from the centre and the ground ends at %.3g m: less than 2 leg reaches "
                  "(%.3g m) to walk before the edge (terrain.half_size_m, placement_half_width_m)",
                  half, c.terrain->half_size_m, 2 * reach);
    out.push_back(what);
  }
  return out;
}

long long Simulator::SelfContactSteps() const {
  return impl_->walker ? impl_->walker->self_contacts().steps() : impl_->self_contacts.steps();
}

std::string Simulator::SelfContactPair() const {
  return impl_->walker ? impl_->walker->self_contacts().MostFrequentPair(impl_->walker->model())
                       : impl_->self_contacts.MostFrequentPair(impl_->model.get());
}

double Simulator::GroundHeight(double x_m, double y_m) const { return impl_->ground->HeightAt(x_m, y_m); }

bool Simulator::LevelGround() const { return !SlopedGround() && PlaneGround(); }

bool Simulator::SlopedGround() const { return impl_->config.slope_deg != 0; }

bool Simulator::PlaneGround() const {
  if (impl_->config.terrain) return false;
  const mjModel* m = impl_->walker ? impl_->walker->model() : impl_->model.get();
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] != 0 || (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0)) continue;
    const mjtNum* q = m->geom_quat + 4 * g;  // a plane faces up when its rotation keeps z
    if (m->geom_type[g] != mjGEOM_PLANE || std::abs(q[1]) > 1e-9 || std::abs(q[2]) > 1e-9) return false;
  }
  return true;
}

Eigen::Vector2d Simulator::TruePitchRoll() const {
  return PitchRollFromGravity(TorsoPose().rotation, impl_->up);
}

Eigen::Vector3d Simulator::Up() const { return impl_->up; }
double Simulator::time_s() const { return impl_->walker ? impl_->walker->time_s() : impl_->time_s; }

double Simulator::total_mass_kg() const {
  return mj_getTotalmass(impl_->walker ? impl_->walker->model() : impl_->model.get());
}

double Simulator::leg_reach_m() const {
  if (impl_->walker) return impl_->walker->robot().reach_m;
  double reach = 0;
  for (const auto& leg : impl_->parts.legs) reach = std::max(reach, leg.coxa_out_m + leg.femur_m + leg.tibia_m);
  return reach;
}

double Simulator::placement_half_width_m() const {
  const double given = impl_->config.placement_half_width_m;
  if (given > 0) return given;
  return impl_->walker ? 2.5 * leg_reach_m() : 1.0;  // the built-in robot: 2.4 of its 0.41 m reach
}

int Simulator::leg_count() const {
  return impl_->walker ? static_cast<int>(impl_->walker->robot().legs.size()) : kNumLegs;
}

const std::array<LegGeometry, kNumLegs>& Simulator::legs() const { return impl_->parts.legs; }
const SimConfig& Simulator::config() const { return impl_->config; }

std::vector<GeomSnapshot> Simulator::Geometry() const {
  const mjModel* m = impl_->walker ? impl_->walker->model() : impl_->model.get();
  const mjData* d = impl_->walker ? impl_->walker->data() : impl_->data.get();
  std::vector<GeomSnapshot> geoms;
  for (int i = 0; i < m->ngeom; ++i) {
    if (m->geom_rgba[4 * i + 3] <= 0) continue;
    GeomSnapshot g;
    switch (m->geom_type[i]) {
      case mjGEOM_PLANE: g.type = GeomSnapshot::Type::kPlane; break;
      case mjGEOM_SPHERE: g.type = GeomSnapshot::Type::kSphere; break;
      case mjGEOM_CAPSULE: g.type = GeomSnapshot::Type::kCapsule; break;
      case mjGEOM_CYLINDER: g.type = GeomSnapshot::Type::kCylinder; break;
      case mjGEOM_BOX: g.type = GeomSnapshot::Type::kBox; break;
      case mjGEOM_HFIELD: g.type = GeomSnapshot::Type::kHeightField; break;
      default: g.type = GeomSnapshot::Type::kOther; break;
    }
    for (int k = 0; k < 3; ++k) {
      g.size[k] = m->geom_size[3 * i + k];
      g.position_m[k] = d->geom_xpos[3 * i + k];
    }
    g.rotation = Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(d->geom_xmat + 9 * i);
    for (int k = 0; k < 4; ++k) g.rgba[k] = m->geom_rgba[4 * i + k];
    if (g.type == GeomSnapshot::Type::kHeightField) {
      const HeightField* field = impl_->ground->field();
      if (!field) continue;  // a height field of the robot's own MJCF: not drawn
      g.grid = field->size();
      g.spacing_m = field->resolution_m();
      g.heights = field->heights();
      g.position_m.setZero();
      g.rotation.setIdentity();
    }
    geoms.push_back(g);
  }
  return geoms;
}

Eigen::Matrix3d SlopeToLevel(double slope_deg) {
  return Eigen::AngleAxisd(-slope_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

}  // namespace dgmm::sim
