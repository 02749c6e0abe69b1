// The per-sample view: raw units from a standardised set.
#include "sim2real/samples.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/sim2real/fake_simulator.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

TEST(RawUnits, UndoesTheTransformAndRefusesAMismatchedOne) {
  const test::FakeSimulator fake;
  SampleSet s = fake.Record({"paper", 2, 4}, {}, 1);
  s.x.conservativeResize(Eigen::NoChange, 2);
  s.x_names.resize(2), s.x_units.resize(2);
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
