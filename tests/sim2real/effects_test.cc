// Shapes of the effect library's designs: the gravity-dependent drifts of a payload or a weak
// leg carry no isotropic downhill creep (that is slope_slip's), stride loss has one fraction per
// axis, and actuator asymmetry treats each direction of a commanded component separately.
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

// Neither a payload nor a weak leg (whose load also shifts with gravity) can produce the
// isotropic downhill creep of slope_slip: lower friction stays a separate explanation.
TEST(Sim2RealEffects, LoadShiftsCannotProduceIsotropicDownhillCreep) {
  const PoseLayout l = SixDof();
  auto lib = EffectLibrary(l, 6, true, true);
  const EffectSpec& slip = Find(lib, "slope_slip");
  const Eigen::VectorXd u = Eigen::VectorXd::Zero(6);
  // Gravity from four headings on an 17.5 degree slope.
  const double h = 0.3, v = -std::sqrt(1 - h * h);
  const Eigen::Vector3d gs[4] = {{h, 0, v}, {0, h, v}, {-h, 0, v}, {0, -h, v}};
  for (const char* key : {"payload_offset", "actuator_asymmetry"}) {
    const EffectSpec& load = Find(lib, key);
    Eigen::MatrixXd a(24, load.num_params()), b(24, 1);
    for (int k = 0; k < 4; ++k) {
      a.middleRows(6 * k, 6) = EffectDesign(load, l, u, gs[k], false);
      b.middleRows(6 * k, 6) = EffectDesign(slip, l, u, gs[k], false);
    }
    const Eigen::VectorXd theta = a.colPivHouseholderQr().solve(b);
    EXPECT_GT((a * theta - b).norm(), 0.5 * b.norm()) << key;
  }
}

// A shorter stride need not shorten the turn: stride loss has one fraction per planar axis.
TEST(Sim2RealEffects, StrideLossHasOneFractionPerAxis) {
  const PoseLayout l = SixDof();
  auto lib = EffectLibrary(l, 6, true, true);
  const EffectSpec& stride = Find(lib, "stride_loss");
  ASSERT_EQ(stride.num_params(), 3);
  Eigen::VectorXd u(6);
  u << 0.3, -0.2, 0.01, 0.002, -0.003, 0.4;
  const Eigen::Vector3d g(0, 0, -1);
  const Eigen::Vector3d theta(0.1, 0.0, 0.0);  // strides 10% shorter, turns unchanged
  const Eigen::VectorXd shift = EffectDesign(stride, l, u, g, false) * theta;
  EXPECT_NEAR(shift(0), -0.03, 1e-12);
  EXPECT_NEAR(shift(1), 0.0, 1e-12);
  EXPECT_NEAR(shift(5), 0.0, 1e-12);
  // Without named planar dimensions it is one fraction of the whole motion.
  PoseLayout unknown;
  auto plain = EffectLibrary(unknown, 6, true, true);
  EXPECT_EQ(Find(plain, "stride_loss").num_params(), 1);
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
