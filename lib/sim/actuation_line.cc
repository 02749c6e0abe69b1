#include "sim/actuation_line.h"

#include <algorithm>
#include <cmath>

namespace dgmm::sim {

std::optional<ServoMap> JointServoMap(const mjModel* m, int a) {
  const double gain = m->actuator_gainprm[mjNGAIN * a];
  const double* b = m->actuator_biasprm + mjNBIAS * a;
  if (m->actuator_trntype[a] != mjTRN_JOINT || m->actuator_gaintype[a] != mjGAIN_FIXED ||
      m->actuator_biastype[a] != mjBIAS_AFFINE || !(b[1] < 0) || gain == 0) {
    return std::nullopt;
  }
  return ServoMap{-b[1] * m->actuator_gear[6 * a] / gain, -b[0] / gain};
}

ActuationLine::ActuationLine(const mjModel* m, std::vector<int> actuators, int latency_steps, double backlash_rad)
    : actuators_(std::move(actuators)), pending_(std::max(0, latency_steps)), half_backlash_(0.5 * backlash_rad) {
  for (int a : actuators_) {
    const bool servo = m->actuator_biastype[a] == mjBIAS_AFFINE && m->actuator_biasprm[mjNBIAS * a + 1] < 0;
    const bool joint = m->actuator_trntype[a] == mjTRN_JOINT;
    backlash_qpos_.push_back(servo && joint ? m->jnt_qposadr[m->actuator_trnid[2 * a]] : -1);
    const ServoMap map = JointServoMap(m, a).value_or(ServoMap{});
    ctrl_scale_.push_back(map.scale);
    ctrl_offset_.push_back(map.offset);
  }
  seen_ = Eigen::VectorXd::Zero(static_cast<int>(actuators_.size()));
}

void ActuationLine::Reset(const Eigen::VectorXd& u) {
  std::fill(pending_.begin(), pending_.end(), u);
  head_ = 0;
  seen_ = u;
}

void ActuationLine::Send(const Eigen::VectorXd& u) {
  if (pending_.empty()) {
    seen_ = u;
    return;
  }
  seen_ = pending_[head_];
  pending_[head_] = u;
  head_ = (head_ + 1) % static_cast<int>(pending_.size());
}

void ActuationLine::Write(mjData* d) const {
  for (std::size_t i = 0; i < actuators_.size(); ++i) {
    double u = seen_[static_cast<int>(i)];
    if (half_backlash_ > 0 && backlash_qpos_[i] >= 0) {
      const double q = d->qpos[backlash_qpos_[i]];
      const double e = u - q;
      u = q + std::copysign(std::max(0.0, std::abs(e) - half_backlash_), e);
    }
    if (ctrl_scale_[i] != 1.0 || ctrl_offset_[i] != 0.0) u = ctrl_offset_[i] + ctrl_scale_[i] * u;
    d->ctrl[actuators_[i]] = u;
  }
}

}  // namespace dgmm::sim
