// Shapes of the effect library's designs: the payload's gravity-dependent drift carries no
// isotropic downhill creep (that is slope_slip's), and actuator asymmetry treats each direction
// of a commanded component separately.
#include "sim2real/effects.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dgmm::sim2real {
namespace {

PoseLayout SixDof() {
  PoseLayout l;
  l.dx = 0, l.dy = 1, l.dz = 2, l.droll = 3, l.dpitch = 4, l.dyaw = 5;
  return l;
}

const EffectSpec& Find(const std::vector<EffectSpec>& lib, const std::string& key) {
  for (const auto& e : lib)
    if (e.key == key) return e;
  ADD_FAILURE() << "no effect " << key;
  return lib.front();
}

TEST(Sim2RealEffects, PayloadCannotProduceIsotropicDownhillCreep) {
  const PoseLayout l = SixDof();
  auto lib = EffectLibrary(l, 6, true, true);
  const EffectSpec& payload = Find(lib, "payload_offset");
  const EffectSpec& slip = Find(lib, "slope_slip");
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(6);
  // Gravity from four headings on an 17.5 degree slope.
  const double h = 0.3, v = -std::sqrt(1 - h * h);
  const Eigen::Vector3d gs[4] = {{h, 0, v}, {0, h, v}, {-h, 0, v}, {0, -h, v}};
  Eigen::MatrixXd a(24, payload.num_params()), b(24, 1);
  for (int k = 0; k < 4; ++k) {
    a.middleRows(6 * k, 6) = EffectDesign(payload, l, u, gs[k], false);
    b.middleRows(6 * k, 6) = EffectDesign(slip, l, u, gs[k], false);
  }
  const Eigen::VectorXd theta = a.colPivHouseholderQr().solve(b);
  EXPECT_GT((a * theta - b).norm(), 0.5 * b.norm());
}

TEST(Sim2RealEffects, AsymmetryTreatsEachDirectionSeparately) {
  const PoseLayout l = SixDof();
  auto lib = EffectLibrary(l, 6, true, true);
  const EffectSpec& asym = Find(lib, "actuator_asymmetry");
  Eigen::VectorXd forward = Eigen::VectorXd::Zero(6), backward = Eigen::VectorXd::Zero(6);
  forward(0) = 0.1;
  backward(0) = -0.1;
  const Eigen::Vector3d g(0, 0, -1);
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(asym.num_params());
  for (int q = 0; q < asym.num_params(); ++q)
    if (asym.parameters[q].name == "yaw_per_m_forward") theta(q) = 0.2;
  const Eigen::VectorXd sf = EffectDesign(asym, l, forward, g, false) * theta;
  const Eigen::VectorXd sb = EffectDesign(asym, l, backward, g, false) * theta;
  EXPECT_NEAR(sf(5), 0.02, 1e-12);
  EXPECT_NEAR(sb(5), 0.0, 1e-12);  // a linear form would give -0.02 walking backwards
}

}  // namespace
}  // namespace dgmm::sim2real
