#include "core/sample_set.h"

#include <gtest/gtest.h>

#include <cmath>

namespace dgmm {
namespace {

SampleSet Valid() {
  SampleSet s;
  s.command_dim_names = {"v"};
  s.commands.resize(2, 1);
  s.commands << 0.1, 0.2;
  s.command_labels = {"a", "b"};
  s.command.resize(3);
  s.command << 0, 1, 1;
  s.x.resize(3, 2);
  s.x << 1, 2, 3, 4, 5, 6;
  s.x_names = {"dx", "dy"};
  s.z.resize(3, 1);
  s.z << 7, 8, 9;
  s.z_names = {"p"};
  s.episode.resize(3);
  s.episode << 0, 0, 1;
  s.step.resize(3);
  s.step << 0, 1, 0;
  return s;
}

// Validate() names the field in its one-line message.
void ExpectInvalid(const SampleSet& s, const std::string& field) {
  const std::string e = s.Validate();
  EXPECT_EQ(e.rfind(field, 0), 0u) << "message: '" << e << "', expected field " << field;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

TEST(SampleSetTest, ValidSetPasses) { EXPECT_EQ(Valid().Validate(), ""); }

TEST(SampleSetTest, ValidateCatchesEachProblem) {
  SampleSet s = Valid();
  s.x(1, 1) = std::nan("");
  ExpectInvalid(s, "x:");
  EXPECT_NE(s.Validate().find("'dy'"), std::string::npos);
  s = Valid();
  s.z(2, 0) = INFINITY;
  ExpectInvalid(s, "z:");
  s = Valid();
  s.x.resize(0, 2);
  s.command.resize(0);
  ExpectInvalid(s, "x:");
  s = Valid();
  s.x_names = {"only one"};
  ExpectInvalid(s, "x names");
  s = Valid();
  s.command[2] = 2;
  ExpectInvalid(s, "command:");
  s = Valid();
  s.command[0] = -1;
  ExpectInvalid(s, "command:");
  s = Valid();
  s.command.resize(2);
  ExpectInvalid(s, "command:");
  s = Valid();
  s.z.resize(2, 1);
  ExpectInvalid(s, "z:");
  s = Valid();
  s.commands.resize(0, 1);
  ExpectInvalid(s, "commands:");
  s = Valid();
  s.command_labels = {"a"};
  ExpectInvalid(s, "command labels");
  s = Valid();
  s.step.resize(0);
  ExpectInvalid(s, "episode/step");
  s = Valid();
  s.transform.offset = Eigen::Vector3d(0, 0, 0);
  s.transform.scale = Eigen::Vector3d(1, 0, 1);
  ExpectInvalid(s, "transform");
  s.transform.scale = Eigen::Vector2d(1, 1);
  ExpectInvalid(s, "transform");
}

TEST(SampleSetTest, SubsetAndJoint) {
  const SampleSet s = Valid();
  const SampleSet sub = s.Subset({2, 0});
  ASSERT_EQ(sub.size(), 2);
  EXPECT_EQ(sub.Validate(), "");
  EXPECT_EQ(sub.command[0], 1);
  EXPECT_EQ(sub.x.row(0), s.x.row(2));
  EXPECT_EQ(sub.z(1, 0), 7);
  EXPECT_EQ(sub.episode[0], 1);
  EXPECT_EQ(sub.step[1], 0);
  EXPECT_EQ(sub.command_labels, s.command_labels);
  EXPECT_EQ(s.Joint(1), Eigen::Vector3d(3, 4, 8));
}

}  // namespace
}  // namespace dgmm
