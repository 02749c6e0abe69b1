#include "sim2real/knob_design.h"

#include <algorithm>

namespace dgmm::sim2real {

Eigen::MatrixXd ExternalDesign(const ExternalCandidate& e, const std::vector<PairedShift>& shifts,
                               const LinearGaussianModel& model, const PoseLayout& layout, int dx, int c,
                               const Eigen::VectorXd& z, double f) {
  switch (e.kind) {
    case ExternalCandidate::kShift: return shifts[e.shifts[0]].Shift(c, z, f);
    case ExternalCandidate::kPayload: {
      Eigen::MatrixXd d(dx, 3);
      const size_t o = e.shifts.size() == 4 ? 1 : 0;  // refined: the probes follow the refined shift
      const Eigen::VectorXd centre = shifts[e.shifts[o]].Shift(c, z, f);
      d.col(0) = o == 1 ? shifts[e.shifts[0]].Shift(c, z, f) : centre;
      d.col(1) = shifts[e.shifts[o + 1]].Shift(c, z, f) - centre;
      d.col(2) = shifts[e.shifts[o + 2]].Shift(c, z, f) - centre;
      return d;
    }
    case ExternalCandidate::kImuBias: {
      // Recorded z = true z + b: the mean at the true z is u(z - b) ~ u(z) - J b.
      Eigen::MatrixXd d = Eigen::MatrixXd::Zero(dx, 2);  // pitch and roll (the first two columns)
      const double h = 1e-3;
      for (int j = 0; j < std::min<int>(2, z.size()); ++j) {
        Eigen::VectorXd zp = z, zm = z;
        zp(j) += h;
        zm(j) -= h;
        d.col(j) = -(model.Predict(c, zp, f).mean - model.Predict(c, zm, f).mean) / (2 * h);
      }
      return d;
    }
    case ExternalCandidate::kHeading: {
      Eigen::MatrixXd d = Eigen::MatrixXd::Zero(dx, 1);
      d(layout.dyaw, 0) = 1.0;
      return d;
    }
    case ExternalCandidate::kTrackerBias: {
      // A constant offset on every pose axis but yaw: a yaw offset per execution is heading drift,
      // its own candidate (with yaw here the bias would nest the drift and absorb it).
      Eigen::MatrixXd d = Eigen::MatrixXd::Zero(dx, layout.dyaw >= 0 ? dx - 1 : dx);
      for (int j = 0, col = 0; j < dx; ++j) {
        if (j != layout.dyaw) d(j, col++) = 1.0;
      }
      return d;
    }
  }
  return Eigen::MatrixXd::Zero(dx, 1);
}

EffectSpec ExternalSpec(const std::string& key, const std::string& title, int params, const std::string& unit) {
  EffectSpec s;
  s.id = EffectId::kExternal;
  s.key = key;
  s.title = title;
  for (int p = 0; p < params; ++p) s.parameters.push_back({"t" + std::to_string(p), unit});
  return s;
}

}  // namespace dgmm::sim2real
