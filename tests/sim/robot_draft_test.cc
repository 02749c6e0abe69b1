// Tests of lib/sim/robot_draft.h: the project's robots are drafted as their shipped configs
// describe them, and models that cannot be drafted are refused naming the part.
#include "sim/robot_draft.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "sim/sim_config.h"
#include "util/error.h"
#include "robot_files.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

using test::kRobots;
using test::ReadText;

// `xml` written to a temporary file for the duration of a test.
class TempModel {
 public:
  explicit TempModel(const std::string& xml)
      : path_(fs::temp_directory_path() /
              ("dgmm_draft_" + std::to_string(::getpid()) + "_" + std::to_string(count_++) + ".xml")) {
    std::ofstream(path_) << xml;
  }
  ~TempModel() { fs::remove(path_); }
  std::string path() const { return path_.string(); }

 private:
  static inline int count_ = 0;
  fs::path path_;
};

// The hexapod's MJCF with `from` replaced by `to`.
std::string EditedHexapod(const std::string& from, const std::string& to) {
  std::string xml = ReadText(kRobots / "hexapod.xml");
  const auto at = xml.find(from);
  if (at != std::string::npos) xml.replace(at, from.size(), to);
  return at == std::string::npos ? "" : xml;
}

std::string ErrorOf(const std::string& xml) {
  TempModel model(xml);
  try {
    DraftRobot(model.path());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RobotDraft, TheProjectsRobotsAreDraftedAsTheirConfigsDescribeThem) {
  for (const char* name : {"hexapod.json", "sprawled_quadruped.json", "planar_quadruped.json",
                           "mammal_quadruped/mammal_quadruped.json", "scorpion_generic.json", "centipede.json"}) {
    SCOPED_TRACE(name);
    const SimConfig shipped = LoadSimConfig((kRobots / name).string());
    const RobotDescription& want = *shipped.robot;
    const RobotDraft draft = DraftRobot(shipped.mjcf_path);
    const RobotDescription& got = draft.robot;
    EXPECT_EQ(got.torso_body, want.torso_body);
    EXPECT_EQ(got.floor_geom, want.floor_geom);
    ASSERT_EQ(got.legs.size(), want.legs.size());
    std::map<std::string, const LegDescription*> by_name;
    for (const auto& leg : got.legs) by_name[leg.name] = &leg;
    for (const auto& leg : want.legs) {
      SCOPED_TRACE(leg.name);
      ASSERT_EQ(by_name.count(leg.name), 1u);
      const LegDescription& drafted = *by_name[leg.name];
      EXPECT_EQ(drafted.joints, leg.joints);
      EXPECT_EQ(drafted.foot.geom, leg.foot.geom);
      if (!leg.side.empty()) EXPECT_EQ(drafted.side, leg.side);
    }
    EXPECT_EQ(got.passive_joints, want.passive_joints);
    EXPECT_EQ(got.held_joints, want.held_joints);  // the centipede's driven spine joint
    // Each draft binds as dgmm simulate binds a robot block (with the generic gait: the mammal's
    // shipped config replays its own controller instead, which a draft cannot guess).
    EXPECT_EQ(draft.bind_error, "");
  }
}

TEST(RobotDraft, ABranchAboveTheFeetIsNotALegAndItsJointsArePassive) {
  // A tail: an undriven hinge on the torso's back, well above the ground.
  const std::string xml = EditedHexapod(
      "<freejoint name=\"root\"/>",
      "<freejoint name=\"root\"/><body name=\"tail\" pos=\"-0.16 0 0.02\"><joint name=\"tail_wag\" type=\"hinge\" "
      "axis=\"0 0 1\" range=\"-30 30\"/><geom type=\"capsule\" fromto=\"0 0 0 -0.1 0 0.03\" size=\"0.01\" "
      "mass=\"0.02\"/></body>");
  ASSERT_NE(xml, "");
  TempModel model(xml);
  const RobotDraft draft = DraftRobot(model.path());
  EXPECT_EQ(draft.robot.legs.size(), 6u);
  EXPECT_EQ(draft.robot.passive_joints, std::vector<std::string>{"tail_wag"});
  EXPECT_EQ(draft.bind_error, "");
  ASSERT_FALSE(draft.notes.empty());
  EXPECT_NE(draft.notes[0].find("\"tail\" does not reach the ground"), std::string::npos) << draft.notes[0];
}

TEST(RobotDraft, ADrivenTailIsHeldAtRest) {
  // The same tail wagged by a position servo: its joint is held (until 2026-12-07 it was listed as
  // passive and the draft did not bind: the tail's servo drove no leg's joint).
  const std::string tail =
      "<freejoint name=\"root\"/><body name=\"tail\" pos=\"-0.16 0 0.02\"><joint name=\"tail_wag\" type=\"hinge\" "
      "axis=\"0 0 1\" range=\"-30 30\"/><geom type=\"capsule\" fromto=\"0 0 0 -0.1 0 0.03\" size=\"0.01\" "
      "mass=\"0.02\"/></body>";
  std::string xml = EditedHexapod("<freejoint name=\"root\"/>", tail);
  ASSERT_NE(xml, "");
  xml.insert(xml.find("</actuator>"), "<position name=\"tail_wag\" joint=\"tail_wag\" kp=\"5\"/>");
  TempModel model(xml);
  const RobotDraft draft = DraftRobot(model.path());
  EXPECT_EQ(draft.robot.legs.size(), 6u);
  EXPECT_EQ(draft.robot.held_joints, std::vector<std::string>{"tail_wag"});
  EXPECT_TRUE(draft.robot.passive_joints.empty());
  EXPECT_EQ(draft.bind_error, "");
  ASSERT_FALSE(draft.notes.empty());
  EXPECT_NE(draft.notes[0].find("held at rest where driven"), std::string::npos) << draft.notes[0];
}

TEST(RobotDraft, AnUnnamedFootIsItsBodyWithTheGeomsOffset) {
  const std::string xml = EditedHexapod("name=\"front_left_foot\" ", "");
  ASSERT_NE(xml, "");
  TempModel model(xml);
  const RobotDraft draft = DraftRobot(model.path());
  const auto& leg = draft.robot.legs[0];
  EXPECT_EQ(leg.name, "front_left");
  EXPECT_EQ(leg.foot.geom, "");
  EXPECT_EQ(leg.foot.body, "front_left_tibia");
  EXPECT_NEAR(leg.foot.offset_m.x(), 0.03, 1e-9);  // the capsule's centre in its body's frame
  EXPECT_NEAR(leg.foot.offset_m.z(), -0.16, 1e-9);
  EXPECT_EQ(draft.bind_error, "");
  // Without a name on the foot's body either, the leg is left out with a note, and the binding
  // says its joints belong to no leg.
  std::string nameless = EditedHexapod("<body name=\"front_left_tibia\"", "<body");
  const std::string foot = "name=\"front_left_foot\" ";
  ASSERT_NE(nameless.find(foot), std::string::npos);
  nameless.replace(nameless.find(foot), foot.size(), "");
  TempModel unnamed(nameless);
  const RobotDraft partial = DraftRobot(unnamed.path());
  EXPECT_EQ(partial.robot.legs.size(), 5u);
  ASSERT_EQ(partial.notes.size(), 1u);
  EXPECT_NE(partial.notes[0].find("\"front_left_coxa\": its lowest geom and that geom's body have no name"),
            std::string::npos)
      << partial.notes[0];
  EXPECT_NE(partial.bind_error.find("front_left_hip_yaw\" belongs to no leg"), std::string::npos) << partial.bind_error;
}

TEST(RobotDraft, ATorsoLongerAcrossTheForwardAxisIsNoted) {
  const SimConfig hexapod = LoadSimConfig((kRobots / "hexapod.json").string());
  RobotDraftOptions sideways;
  sideways.forward_axis = Eigen::Vector3d::UnitY();
  const RobotDraft draft = DraftRobot(hexapod.mjcf_path, sideways);
  ASSERT_EQ(draft.notes.size(), 1u);
  EXPECT_NE(draft.notes[0].find("the torso is longest along 1,0,0"), std::string::npos) << draft.notes[0];
  EXPECT_TRUE(DraftRobot(hexapod.mjcf_path).notes.empty());
  int left = 0;
  for (const auto& leg : draft.robot.legs) left += leg.side == "left";
  EXPECT_EQ(left, 2);  // the front legs are on the left of +y
}

// Servos soft for the robot's weight (the hexapod at kp 10 of 80: a foot gives about a quarter of
// the stride) get the gait's servo feedforward, with a note; the shipped hexapod does not need it;
// the sprawled quadruped at kp 30 of 160 gives as much, but its passive ankles give too: left off.
TEST(RobotDraft, SoftServosGetTheServoFeedforwardUnlessTheLegsHavePassiveJoints) {
  TempModel soft(EditedHexapod(R"(position kp="80")", R"(position kp="10")"));
  const RobotDraft draft = DraftRobot(soft.path());
  EXPECT_TRUE(draft.bind_error.empty()) << draft.bind_error;
  EXPECT_TRUE(draft.robot.gait.servo_feedforward);
  ASSERT_EQ(draft.notes.size(), 1u);
  EXPECT_NE(draft.notes[0].find("servo_feedforward on"), std::string::npos) << draft.notes[0];
  EXPECT_FALSE(DraftRobot(LoadSimConfig((kRobots / "hexapod.json").string()).mjcf_path).robot.gait.servo_feedforward);
  std::string sprawled = ReadText(kRobots / "sprawled_quadruped.xml");
  const std::string from = R"(position kp="160")";
  ASSERT_NE(sprawled.find(from), std::string::npos);
  sprawled.replace(sprawled.find(from), from.size(), R"(position kp="30")");
  TempModel ankles(sprawled);
  const RobotDraft passive = DraftRobot(ankles.path());
  EXPECT_FALSE(passive.robot.gait.servo_feedforward);
  bool noted = false;
  for (const auto& note : passive.notes) noted |= note.find("passive joints give too") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(RobotDraft, ModelsThatCannotBeDraftedAreRefusedNamingThePart) {
  EXPECT_NE(ErrorOf(EditedHexapod("<freejoint name=\"root\"/>", "")).find("one body with a free joint"),
            std::string::npos);
  EXPECT_NE(ErrorOf(EditedHexapod("type=\"plane\"", "type=\"box\"")).find("no named plane geom"), std::string::npos);
  EXPECT_NE(ErrorOf("<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"1 1 0.1\"/><body name=\"b\" "
                    "pos=\"0 0 1\"><freejoint/><geom type=\"sphere\" size=\"0.1\"/></body></worldbody></mujoco>")
                .find("no jointed branch below the torso reaches the ground"),
            std::string::npos);
  const std::string missing = (fs::temp_directory_path() / "dgmm_no_such_model.xml").string();
  try {
    DraftRobot(missing);
    ADD_FAILURE() << "a missing file was drafted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  RobotDraftOptions vertical;
  vertical.forward_axis = Eigen::Vector3d::UnitZ();
  EXPECT_THROW(DraftRobot((kRobots / "hexapod.xml").string(), vertical), InputError);
}

}  // namespace
}  // namespace dgmm::sim
