#include "render/model_slice.h"

#include <gtest/gtest.h>

#include <cmath>

#include "util/error.h"

namespace dgmm {
namespace {

// Pose (dx, dy) and terrain (pitch, roll), stored standardised with a transform.
MotionModel FourDimModel() {
  MotionModel model;
  model.pose_dim = 2;
  model.terrain_dim = 2;
  model.pose_names = {"dx", "dy"};
  model.pose_units = {"m", "m"};
  model.terrain_names = {"pitch", "roll"};
  Eigen::MatrixXd s(4, 4);
  s << 1.0, 0.3, 0.2, 0.1,  //
      0.3, 2.0, -0.4, 0.2,  //
      0.2, -0.4, 1.5, 0.3,  //
      0.1, 0.2, 0.3, 1.0;
  Mixture m(4);
  m.Add(2, Gaussian(Eigen::Vector4d(0.5, -0.2, 0.1, 0.3), s));
  m.Add(1, Gaussian(Eigen::Vector4d(-1.0, 1.0, -0.5, 0.0), 0.5 * s));
  model.mixtures[3] = m;
  model.command_labels[3] = "forward";
  model.transform.offset = Eigen::Vector4d(10, 20, 0, 0);
  model.transform.scale = Eigen::Vector4d(2, 0.5, 0.1, 0.1);
  return model;
}

double LogAt(const Mixture& m, double u, double v) { return m.LogDensity(Eigen::Vector2d(u, v)); }

TEST(ModelSliceTest, ConditionEqualsRawConditionalOfTheModel) {
  const MotionModel model = FourDimModel();
  SliceSpec spec;
  spec.x_dim = "dy";
  spec.y_dim = "dx";
  spec.conditions = {{"roll", 0.02}, {"pitch", -0.01}};
  const ModelSlice slice = SliceModel(model, spec, "m.h5");
  EXPECT_EQ(slice.command, 3);
  EXPECT_EQ(slice.x_index, 1);
  EXPECT_EQ(slice.y_index, 0);
  EXPECT_EQ(slice.x_label, "dy (m)");
  // Reference: raw mixture conditioned on (pitch, roll), then reordered to (dy, dx).
  const Mixture raw = RawMixture(model, 3);
  const Mixture cond = raw.Conditional({2, 3}, Eigen::Vector2d(-0.01, 0.02));  // over (dx, dy)
  for (double u : {19.0, 20.0, 21.5}) {
    for (double v : {8.0, 10.5}) {
      EXPECT_NEAR(LogAt(slice.mixture, u, v), LogAt(cond, v, u), 1e-9);
    }
  }
  EXPECT_NE(slice.description.find("pitch=-0.01"), std::string::npos);
}

TEST(ModelSliceTest, MarginaliseEqualsMarginalAndIsRequired) {
  const MotionModel model = FourDimModel();
  SliceSpec spec;  // default: dx, dy
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
  spec.marginalise = true;
  const ModelSlice slice = SliceModel(model, spec, "m.h5");
  const Mixture marginal = RawMixture(model, 3).Marginal({0, 1});
  EXPECT_NEAR(LogAt(slice.mixture, 10.3, 19.9), LogAt(marginal, 10.3, 19.9), 1e-12);
  EXPECT_NE(slice.description.find("marginal over pitch,roll"), std::string::npos);
}

TEST(ModelSliceTest, RawUnitsUndoTheStandardisation) {
  const MotionModel model = FourDimModel();
  const Mixture raw = RawMixture(model, 3);
  const Gaussian& g = model.mixtures.at(3).component(0);
  EXPECT_NEAR(raw.component(0).mean()(0), 10 + 2 * g.mean()(0), 1e-12);
  EXPECT_NEAR(raw.component(0).covariance()(1, 1), 0.25 * g.covariance()(1, 1), 1e-12);
}

TEST(ModelSliceTest, BadSelectionsAreInputErrors) {
  const MotionModel model = FourDimModel();
  SliceSpec spec;
  spec.marginalise = true;
  spec.x_dim = "nope";
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
  spec.x_dim = "dx";
  spec.y_dim = "dx";
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
  spec.y_dim = "dy";
  spec.conditions = {{"dx", 1.0}};
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
  spec.conditions = {{"pitch", NAN}};
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
  spec.conditions.clear();
  spec.command = "7";
  EXPECT_THROW(SliceModel(model, spec, "m.h5"), InputError);
}

// A condition whose distance from every component overflows has no conditional, also when the
// mixture has a single component (whose weight would renormalise to 1): issue #13's
// `render --condition pitch=1e308` drew a blank picture with exit 0.
TEST(ModelSliceTest, ConditionBeyondEveryComponentIsRefusedForOneComponentToo) {
  MotionModel model = FourDimModel();
  Mixture one(4);
  one.Add(2, model.mixtures[3].component(0));
  model.mixtures[3] = one;
  SliceSpec spec;
  spec.marginalise = true;
  for (double far : {1e308, -1e308}) {
    spec.conditions = {{"pitch", far}};
    try {
      SliceModel(model, spec, "m.h5");
      ADD_FAILURE() << "pitch=" << far << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not a number"), std::string::npos) << e.what();
    }
  }
  spec.conditions = {{"pitch", 0.5}};  // far from the data (sd 0.12) but a number: drawn
  EXPECT_NO_THROW(SliceModel(model, spec, "m.h5"));
}

TEST(ModelSliceTest, CommandsByIdOrLabel) {
  MotionModel model = FourDimModel();
  EXPECT_EQ(ResolveCommand(model, "", "m.h5"), 3);
  EXPECT_EQ(ResolveCommand(model, "forward", "m.h5"), 3);
  EXPECT_EQ(ResolveCommand(model, "3", "m.h5"), 3);
  model.mixtures[5] = model.mixtures[3];
  EXPECT_THROW(ResolveCommand(model, "", "m.h5"), InputError);  // ambiguous
  EXPECT_EQ(ResolveCommand(model, "5", "m.h5"), 5);
}

TEST(ModelSliceTest, PointsOfOneCommandInRawUnits) {
  SampleSet set;
  set.commands = Eigen::MatrixXd::Zero(2, 0);
  set.command_labels = {"a", "b"};
  set.command = Eigen::Vector3i(0, 1, 1);
  set.x = Eigen::MatrixXd(3, 2);
  set.x << 1, 2, 3, 4, 5, 6;
  set.transform.offset = Eigen::Vector2d(1, 0);
  set.transform.scale = Eigen::Vector2d(10, 2);
  const Eigen::MatrixX2d p = SlicePoints(set, 1, 1, 0);
  ASSERT_EQ(p.rows(), 2);
  EXPECT_DOUBLE_EQ(p(0, 0), 8);   // dy = 0 + 2 * 4
  EXPECT_DOUBLE_EQ(p(0, 1), 31);  // dx = 1 + 10 * 3
  EXPECT_THROW(SlicePoints(set, 1, 2, 0), InputError);
}

}  // namespace
}  // namespace dgmm
