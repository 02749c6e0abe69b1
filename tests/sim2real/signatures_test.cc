// A knob's signature: the paired shift of a perturbed recording, linear in terrain per command.
#include "sim2real/signatures.h"

#include <gtest/gtest.h>

#include <random>


namespace dgmm::sim2real {
namespace {

// A paper-protocol-like set: `episodes` placements of 5 steps, commands cycling over 3.
SampleSet MakeSet(int episodes, std::uint64_t seed) {
  SampleSet s;
  s.command_dim_names = {"long"};
  s.commands = Eigen::MatrixXd(3, 1);
  s.commands << -0.5, 0.5, 1.0;
  s.command_labels = {"a", "b", "c"};
  const int n = 5 * episodes;
  s.command.resize(n);
  s.episode.resize(n);
  s.step.resize(n);
  s.x.resize(n, 2);
  s.z.resize(n, 2);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  for (int i = 0; i < n; ++i) {
    s.episode(i) = i / 5;
    s.step(i) = i % 5;
    s.command(i) = (i / 5) % 3;
    s.z(i, 0) = 0.3 * std::sin(i / 5);
    s.z(i, 1) = 0.3 * std::cos(i / 5);
    s.x(i, 0) = 0.1 * s.command(i) + 0.01 * unit(rng);
    s.x(i, 1) = 0.01 * unit(rng);
  }
  s.x_names = {"dx", "dy"};
  s.z_names = {"pitch", "roll"};
  return s;
}

TEST(PairedShift, RecoversAPlantedShiftLinearInTerrain) {
  const SampleSet nominal = MakeSet(30, 1);
  SampleSet perturbed = nominal;
  for (int i = 0; i < perturbed.size(); ++i) {
    perturbed.x(i, 0) += 0.02 * (perturbed.command(i) + 1) + 0.05 * perturbed.z(i, 0);
    perturbed.x(i, 1) -= 0.01;
  }
  const PairedShift shift = PairedShift::Fit(nominal, perturbed, nominal, 0.0);
  EXPECT_EQ(shift.pairs(), nominal.size());
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector2d z(0.2, -0.1);
    const Eigen::VectorXd s = shift.Shift(c, z, 0.0);
    EXPECT_NEAR(s(0), 0.02 * (c + 1) + 0.05 * 0.2, 1e-6);
    EXPECT_NEAR(s(1), -0.01, 1e-6);
  }
  EXPECT_NEAR(shift.log_variance_ratio()(1), 0.0, 1e-9);  // a pure shift leaves the spread alone
}

// Continuous commands are conditioning dimensions (z = pitch, roll, then the commanded velocity):
// a knob whose effect grows with the commanded speed, e.g. slip, has a signature linear in it.
TEST(PairedShift, IsLinearInContinuousCommandsCarriedInZ) {
  SampleSet nominal = MakeSet(40, 2);
  nominal.commands = Eigen::MatrixXd::Zero(1, 1);
  nominal.command_labels = {"velocity"};
  nominal.command.setZero();
  nominal.z.conservativeResize(Eigen::NoChange, 3);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> speed(-0.5, 0.5);
  for (int i = 0; i < nominal.size(); ++i) nominal.z(i, 2) = speed(rng);
  nominal.z_names = {"pitch", "roll", "cmd_long"};
  SampleSet perturbed = nominal;
  for (int i = 0; i < perturbed.size(); ++i) perturbed.x(i, 0) += -0.3 * perturbed.z(i, 2) + 0.02 * perturbed.z(i, 1);
  const PairedShift shift = PairedShift::Fit(nominal, perturbed, nominal, 0.0);
  for (double v : {-0.4, 0.0, 0.45}) {
    const Eigen::Vector3d z(0.1, -0.2, v);
    EXPECT_NEAR(shift.Shift(0, z, 0.0)(0), -0.3 * v + 0.02 * -0.2, 1e-6) << "command " << v;
    EXPECT_NEAR(shift.Shift(0, z, 1.0)(1), 0.0, 1e-6);
  }
}

}  // namespace
}  // namespace dgmm::sim2real
