// The per-sample view: raw units from a standardised set.
#include "sim2real/samples.h"

#include <gtest/gtest.h>

#include <random>

#include "util/error.h"

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

TEST(RawUnits, UndoesTheTransformAndRefusesAMismatchedOne) {
  SampleSet s = MakeSet(4, 2);
  SampleSet standardised = s;
  standardised.transform.offset = Eigen::VectorXd::Constant(4, 1.0);
  standardised.transform.scale = Eigen::VectorXd::Constant(4, 2.0);
  const SampleSet raw = ToRawUnits(standardised, "--real");
  EXPECT_TRUE(raw.transform.empty());
  EXPECT_NEAR(raw.x(3, 0), 1.0 + 2.0 * s.x(3, 0), 1e-12);
  EXPECT_NEAR(raw.z(2, 1), 1.0 + 2.0 * s.z(2, 1), 1e-12);
  standardised.transform.scale = Eigen::VectorXd::Constant(3, 2.0);
  EXPECT_THROW(ToRawUnits(standardised, "--real"), InputError);
}

}  // namespace
}  // namespace dgmm::sim2real
