#include "sim/generic_walker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/gait_reach.h"
#include "sim/ground.h"
#include "sim/simulator.h"
#include "util/error.h"

namespace dgmm::sim {

int ControlEvery(double period_s, double timestep_s) {
  const double control_s = std::min(kControlPeriodS, period_s / kControlsPerCycle);
  return std::max(1, static_cast<int>(std::lround(control_s / timestep_s)));
}

GenericWalker::GenericWalker(const SimConfig& config, MjModelPtr model, const Ground& ground, const std::string& source)
    : config_(config), model_(std::move(model)), ground_(&ground), source_(source) {
  robot_ = BindRobot(model_.get(), *config.robot, source);
  for (const LegChain& leg : robot_.legs) sides_.push_back(leg.side);
  std::vector<Eigen::Vector2d> stance;
  for (const LegChain& leg : robot_.legs) stance.push_back(leg.stance_m.head<2>());
  sway_ = SwayTargets(stance, ResolveSway(config.robot->gait.sway, robot_.timing.duty));
  if (config.robot->gait.servo_feedforward && robot_.replay.empty()) {
    feedforward_ = ServoFeedforward(model_.get(), robot_, config.robot->gait.period_s);  // nominal: before the experiment
  }
  ApplyExperiment(config, robot_, model_.get(), source);
  control_every_ = ControlEvery(config.robot->gait.period_s, config.timestep_s);
}

void GenericWalker::Start() {
  data_.reset(mj_makeData(model_.get()));
  scratch_.reset(mj_makeData(model_.get()));
  for (int k = 0; k < 7; ++k) scratch_->qpos[robot_.torso_qpos + k] = k == 3 ? 1 : 0;  // torso frame = world
  for (std::size_t i = 0; i < robot_.held_qpos.size(); ++i) scratch_->qpos[robot_.held_qpos[i]] = robot_.held_q[i];
  mj_setConst(model_.get(), data_.get());
  q_.resize(robot_.legs.size());
  std::vector<int> actuators = robot_.leg_actuators;  // then the held joints' servos
  actuators.insert(actuators.end(), robot_.held_actuators.begin(), robot_.held_actuators.end());
  if (!robot_.replay.empty()) {
    actuators.clear();
    for (int a = 0; a < model_->nu; ++a) actuators.push_back(a);
  }
  const int latency_steps = static_cast<int>(std::lround(config_.actuators.latency_s / model_->opt.timestep));
  line_ = ActuationLine(model_.get(), actuators, latency_steps, config_.actuators.backlash_rad);
}

bool GenericWalker::Step() {
  line_.Send(u_);
  line_.Write(data_.get());
  time_s_ += model_->opt.timestep;
  const bool ok = StepChecked(model_.get(), data_.get());
  self_contacts_.Observe(model_.get(), data_.get());
  return ok;
}

std::vector<Eigen::Vector3d> GenericWalker::FootPoints() const {
  std::vector<Eigen::Vector3d> feet;
  for (const LegChain& leg : robot_.legs) feet.push_back(FootPoint(model_.get(), data_.get(), leg));
  return feet;
}

Pose GenericWalker::RobotPose() const {
  Pose pose;
  const int b = robot_.torso_body;
  pose.position_m = Eigen::Vector3d(data_->xpos[3 * b], data_->xpos[3 * b + 1], data_->xpos[3 * b + 2]);
  const Eigen::Matrix3d torso = Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(data_->xmat + 9 * b);
  pose.rotation = torso * robot_.robot_in_torso;
  return pose;
}

bool GenericWalker::Fallen() const {
  const Pose pose = RobotPose();
  const double kMaxTiltCos = 0.5;      // 60 degrees from the slope normal
  const double kMinHeightShare = 0.4;  // of the stance height
  // From the mean ground under the feet: a stone under the belly is no fall.
  const double ground_m = ground_->field() ? ground_->MeanUnder(FootPoints()) : 0.0;
  return pose.rotation(2, 2) < kMaxTiltCos || pose.position_m.z() - ground_m < kMinHeightShare * robot_.stance_height_m;
}

void GenericWalker::HoldStance() {
  if (!robot_.replay.empty()) {
    u_ = robot_.replay[robot_.stand_recording].At(0);
  } else {
    StanceTargets();
  }
  line_.Reset(u_);
  line_.Write(data_.get());
}

void GenericWalker::StanceTargets() {
  const int legs = static_cast<int>(robot_.leg_actuators.size());
  u_.resize(legs + robot_.held_q.size());
  u_.tail(robot_.held_q.size()) = robot_.held_q;
  int k = 0;
  std::vector<Eigen::Vector3d> feet;
  for (std::size_t i = 0; i < robot_.legs.size(); ++i) {
    q_[i] = robot_.legs[i].stance_q;
    for (int j = 0; j < q_[i].size(); ++j) u_[k++] = q_[i][j];
    feet.push_back(robot_.legs[i].stance_m);
  }
  if (!feedforward_.enabled()) return;
  const double* w = data_->qpos + robot_.torso_qpos + 3;  // not xmat: it may predate a placement
  const Eigen::Matrix3d torso = Eigen::Quaterniond(w[0], w[1], w[2], w[3]).toRotationMatrix();
  const LegPlan plan{q_, {}, feet, Support(), GravityAtHeading(torso * robot_.robot_in_torso)};
  u_.head(legs) += feedforward_.Offsets(model_.get(), scratch_.get(), robot_, plan);
}

const ReplayTrack& GenericWalker::Recording(const Eigen::Vector3d& c) const {
  const int i = FindRecording(config_.robot->controller, c);
  if (i < 0) {
    char what[160];
    std::snprintf(what, sizeof what, "no recording of command [%g, %g, %g]", c.x(), c.y(), c.z());
    throw MakeInputError(source_, "robot.controller.recordings", what);
  }
  return robot_.replay[i];
}

RunOutcome GenericWalker::Place(double x_m, double y_m, double heading_rad) {
  mjModel* m = model_.get();
  mjData* d = data_.get();
  mj_resetData(m, d);
  if (m->nkey > 0) mju_copy(d->qpos, m->key_qpos, m->nq);
  double extent = 0;
  for (std::size_t i = 0; i < robot_.legs.size(); ++i) {
    const LegChain& leg = robot_.legs[i];
    for (std::size_t k = 0; k < leg.qpos.size(); ++k) d->qpos[leg.qpos[k]] = leg.stance_q[k];
    extent = std::max(extent, leg.foot_extent_m);
  }
  const Eigen::Matrix3d world = Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                robot_.robot_in_torso.transpose();
  const Eigen::Quaterniond q(world);
  const double kDrop = 0.02 * robot_.reach_m;  // released just above the ground under the highest foot
  std::vector<Eigen::Vector2d> stance;
  for (const LegChain& leg : robot_.legs) stance.push_back(leg.stance_m.head<2>());
  const double ground_m = ground_->HighestUnder(x_m, y_m, heading_rad, stance);
  const int a = robot_.torso_qpos;
  d->qpos[a + 0] = x_m;
  d->qpos[a + 1] = y_m;
  d->qpos[a + 2] = ground_m + robot_.stance_height_m + extent + kDrop;
  d->qpos[a + 3] = q.w();
  d->qpos[a + 4] = q.x();
  d->qpos[a + 5] = q.y();
  d->qpos[a + 6] = q.z();
  support_.assign(robot_.legs.size(), 0.0);  // released in the air
  HoldStance();
  mj_forward(m, d);
  return Stand(config_.settle_duration_s);
}

RunOutcome GenericWalker::Stand(double seconds) {
  HoldStance();
  const double dt = model_->opt.timestep;
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int s = 0; s < steps; ++s) {
    if (!robot_.replay.empty()) u_ = robot_.replay[robot_.stand_recording].At((s + 1) * dt);
    if (feedforward_.enabled() && s > 0 && s % control_every_ == 0) StanceTargets();  // s = 0: HoldStance's
    if (!Step()) return RunOutcome::kUnstable;
    if (Fallen()) return RunOutcome::kFell;
  }
  return RunOutcome::kCompleted;
}

// Foot targets of the generic gait at time t of a command, through inverse kinematics to joint
// targets: each foot travels d_i = duty (stride (long, lat) + turn_rad turn z x p_i) per stance,
// so the torso moves stride per cycle and turns turn_rad per cycle (backward commands swing the
// legs in the reversed order, GaitTiming::phase_backward, and a side-sequential pattern starts a
// sideways command with its trailing side, LateralShift); a ramp of a tenth of a cycle at
// either end of the command starts and ends the pattern at the stance; the stance leans with
// gravity (robot.gait.lean) and, in statically stable gaits, sways towards the centroid of the
// feet that stay down while each leg swings (robot.gait.sway); with robot.gait.servo_feedforward
// the targets carry the loads the servos will meet (servo_feedforward.h).
void GenericWalker::Control(const Eigen::Vector3d& c, double t, double duration) {
  const double period = config_.robot->gait.period_s;
  const double ramp = 0.1 * period;
  const double envelope = std::clamp(std::min(t, duration - t) / ramp, 0.0, 1.0);
  const double duty = robot_.timing.duty;
  // Lean: every foot shifted by lean x (where the gravity line through the torso meets the foot
  // plane), so that the support polygon stays under the centre of mass on a slope. From the
  // ground's tilt at the robot's heading, not the torso's own wobble (no feedback loop).
  Eigen::Vector3d lean = Eigen::Vector3d::Zero();
  const Eigen::Matrix3d robot = RobotPose().rotation;
  const Eigen::Vector3d g = GravityAtHeading(robot);
  if (g.z() < -0.5) lean.head<2>() = config_.robot->gait.lean * robot_.stance_height_m * g.head<2>() / -g.z();
  const std::vector<double>& phase = c.x() < 0 ? robot_.timing.phase_backward : robot_.timing.phase;
  const double shift = LateralShift(robot_.timing, phase, sides_, c.y());
  const std::size_t n = robot_.legs.size();
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = t / period - phase[i] - shift;
  Eigen::Vector3d sway = Eigen::Vector3d::Zero();  // the torso moves by +sway: every foot by -sway
  sway.head<2>() = envelope * Sway(u);
  const Eigen::Matrix3d back = LevelBack(robot, config_.robot->gait.level);
  std::vector<Eigen::Vector3d> targets(n);
  for (std::size_t i = 0; i < n; ++i) {
    const LegChain& leg = robot_.legs[i];
    const Eigen::Vector2d d = FootTravel(robot_, leg, c, config_.robot->gait.turn_rad);
    const Eigen::Vector3d p = leg.stance_m + lean - sway + envelope * FootOffset(u[i], duty, d, robot_.step_height_m);
    targets[i] = robot_.robot_in_torso * (config_.robot->gait.level > 0 ? Eigen::Vector3d(back * p) : p);
  }
  std::vector<Eigen::VectorXd> before;  // the last targets sent
  if (feedforward_.enabled()) before = q_;
  SolveLegsIk(model_.get(), scratch_.get(), robot_.legs, targets, &q_, 3);
  int k = 0;
  for (std::size_t i = 0; i < robot_.legs.size(); ++i) {
    for (int j = 0; j < q_[i].size(); ++j) u_[k++] = q_[i][j];
  }
  if (!feedforward_.enabled()) return;
  LegPlan plan{q_, {}, {}, Support(), g};
  for (std::size_t i = 0; i < n; ++i) {
    plan.q_velocity.push_back((q_[i] - before[i]) / (control_every_ * model_->opt.timestep));
    plan.feet_robot_m.push_back(robot_.robot_in_torso.transpose() * targets[i]);
  }
  const int legs = static_cast<int>(robot_.leg_actuators.size());
  u_.head(legs) += feedforward_.Offsets(model_.get(), scratch_.get(), robot_, plan);
}

const std::vector<double>& GenericWalker::Support() {
  const std::vector<double> on = feedforward_.OnGround(model_.get(), data_.get(), robot_.torso_body);
  // A first-order filter over a twentieth of a cycle: contacts chatter, the load moves over smoothly.
  const double rate = std::min(1.0, control_every_ * model_->opt.timestep / (0.05 * config_.robot->gait.period_s));
  support_.resize(on.size(), 0.0);
  for (std::size_t i = 0; i < on.size(); ++i) support_[i] += rate * (on[i] - support_[i]);
  return support_;
}

namespace {
// Rz(yaw) of a rotation R: its heading about the slope frame's z.
Eigen::AngleAxisd Heading(const Eigen::Matrix3d& r) {
  return Eigen::AngleAxisd(std::atan2(r(1, 0), r(0, 0)), Eigen::Vector3d::UnitZ());
}
}  // namespace

Eigen::Matrix3d LevelBack(const Eigen::Matrix3d& r, double level) {
  if (level == 0) return Eigen::Matrix3d::Identity();
  const Eigen::AngleAxisd tilt(Heading(r).inverse() * r);
  return Eigen::AngleAxisd(-level * tilt.angle(), tilt.axis()).toRotationMatrix();
}

Eigen::Vector3d GenericWalker::GravityAtHeading(const Eigen::Matrix3d& r) const {
  return Heading(r).inverse() *
         Eigen::Vector3d(model_->opt.gravity[0], model_->opt.gravity[1], model_->opt.gravity[2]).normalized();
}

Eigen::Vector2d GenericWalker::Sway(const std::vector<double>& u) const {
  Eigen::Vector2d b = Eigen::Vector2d::Zero();  // sum over legs of weight(u_i) x target_i
  for (std::size_t i = 0; i < u.size(); ++i) b += SwingWeight(u[i], robot_.timing.duty) * sway_[i];
  return b;
}

RunOutcome GenericWalker::Run(const Eigen::Vector3d& command, const std::function<void(int)>& observe) {
  const double dt = model_->opt.timestep;
  const double duration = config_.command_duration_s;
  const int steps = static_cast<int>(std::lround(duration / dt));
  const Eigen::Vector3d c = command.cwiseMax(-1.0).cwiseMin(1.0);
  const ReplayTrack* track = robot_.replay.empty() ? nullptr : &Recording(command);
  for (int s = 0; s < steps; ++s) {
    if (track) {
      u_ = track->At((s + 1) * dt);
    } else if (s % control_every_ == 0) {
      Control(c, (s + 1) * dt, duration);
    }
    if (!Step()) return RunOutcome::kUnstable;
    if (observe) observe(s);
    if (Fallen()) return RunOutcome::kFell;
  }
  return RunOutcome::kCompleted;
}

}  // namespace dgmm::sim
