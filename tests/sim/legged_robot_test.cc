// Any legged robot described in a config's robot block (lib/sim/robot_description.h,
// legged_robot.h, generic_walker.h), on the project's own hexapod (datasets/robots/hexapod.xml)
// and variants of it that must be refused.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "sim/generic_walker.h"
#include "sim/ground.h"
#include "sim/legged_robot.h"
#include "sim/mujoco_model.h"
#include "sim/protocol.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"
#include "robot_files.h"

namespace dgmm::sim {
namespace {

namespace fs = std::filesystem;

using test::kRobots;
using test::ReadText;

SimConfig Hexapod(double slope_deg = 0) {
  SimConfig c = LoadSimConfig((kRobots / "hexapod.json").string());
  c.slope_deg = slope_deg;
  return c;
}

// A project robot's MJCF (datasets/robots/<robot>.xml) with `from` replaced by `to`, written to a
// temporary file; its config (flat ground) with the robot block edited by `edit`. Returns the
// error message of building a Simulator ("" if none).
template <typename Edit>
std::string ErrorOfRobot(const std::string& robot, const std::string& from, const std::string& to, Edit edit) {
  std::string xml = ReadText(kRobots / (robot + ".xml"));
  if (!from.empty()) {
    const auto at = xml.find(from);
    if (at == std::string::npos) return "test setup: text not found: " + from;
    xml.replace(at, from.size(), to);
  }
  const fs::path path = fs::temp_directory_path() / ("dgmm_legged_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig c = LoadSimConfig((kRobots / (robot + ".json")).string());
  c.slope_deg = 0;
  c.mjcf_path = path.string();
  edit(&*c.robot);
  std::string error;
  try {
    Simulator sim(c);
  } catch (const std::exception& e) {
    error = e.what();
  }
  fs::remove(path);
  return error;
}
// The hexapod's (datasets/robots/hexapod.xml), the robot most refusals are shown on.
template <typename Edit>
std::string ErrorOf(const std::string& from, const std::string& to, Edit edit) {
  return ErrorOfRobot("hexapod", from, to, edit);
}
std::string ErrorOf(const std::string& from, const std::string& to) {
  return ErrorOf(from, to, [](RobotDescription*) {});
}

TEST(LeggedRobot, TheHexapodWalksAsCommandedOnFlatGround) {
  Simulator sim(Hexapod());
  const RobotDescription& r = *sim.config().robot;
  const double cycles = sim.config().command_duration_s / r.gait.period_s;
  const double stride = r.gait.stride_reach * sim.leg_reach_m() * cycles;  // per command at |c| = 1
  ASSERT_EQ(sim.leg_count(), 6);
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0.5, 0, 0)), RunOutcome::kCompleted);
  const Eigen::Vector3d moved = start.rotation.transpose() * (sim.TorsoPose().position_m - start.position_m);
  EXPECT_NEAR(moved.x() / (0.5 * stride), 1.0, 0.25);
  EXPECT_LT(std::abs(moved.y()) / (0.5 * stride), 0.15);
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose before = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0, 0, -0.5)), RunOutcome::kCompleted);
  const Eigen::Matrix3d turn = before.rotation.transpose() * sim.TorsoPose().rotation;
  const double yaw = std::atan2(turn(1, 0), turn(0, 0));
  EXPECT_NEAR(yaw / (-0.5 * r.gait.turn_rad * cycles), 1.0, 0.3);
}

TEST(LeggedRobot, LevelBackTakesTheTiltBackAndKeepsTheHeading) {
  using Eigen::AngleAxisd;
  const Eigen::Matrix3d heading = AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d r = heading * AngleAxisd(0.3, Eigen::Vector3d::UnitY()) * AngleAxisd(-0.2, Eigen::Vector3d::UnitX());
  EXPECT_TRUE(LevelBack(r, 0).isIdentity(0));
  const Eigen::Vector3d p(0.1, -0.05, -0.09);  // a foot's target in the robot frame
  EXPECT_TRUE((r * LevelBack(r, 1) * p).isApprox(heading * p, 1e-12)) << "all of the tilt taken back";
  const double tilt = AngleAxisd(heading.transpose() * r).angle();
  EXPECT_NEAR(AngleAxisd(heading.transpose() * r * LevelBack(r, 0.5)).angle(), 0.5 * tilt, 1e-12);
}

// Walking five commands from each of 20 places on the hexapod's rough ground: the torso's tilt
// from the slope plane drifts with the targets in its own frame, and far less with most of it
// taken back (robot.gait.level).
int TiltedAfterFiveCommands(double level) {
  SimConfig c = LoadSimConfig((kRobots / "hexapod_rough_ground.json").string());
  c.robot->gait.level = level;
  Simulator sim(c);
  int tilted = 0;
  for (int p = 0; p < 20; ++p) {
    if (sim.Place(-1.0 + 0.5 * (p % 5), -0.75 + 0.5 * (p / 5), 0.5 * p) != RunOutcome::kCompleted) continue;
    for (int k = 0; k < 5; ++k) {
      if (sim.RunCommand(Eigen::Vector3d(k % 2 ? 0.5 : -0.5, 0, 0.25)) != RunOutcome::kCompleted) break;
    }
    tilted += TiltedBeyondThreshold(sim.TorsoPose());
  }
  return tilted;
}

TEST(LeggedRobot, LevelingKeepsTheHexapodFromTiltingOnItsRoughGround) {
  const int open_loop = TiltedAfterFiveCommands(0), leveled = TiltedAfterFiveCommands(0.75);
  EXPECT_GE(open_loop, 5) << "the drift this guards against, of 20 places";
  EXPECT_LE(leveled, open_loop / 2);
}

TEST(LeggedRobot, TheLevelIsWrittenOnlyWhenSetAndReadBack) {
  SimConfig c = Hexapod();
  EXPECT_EQ(SimConfigToJson(c).find("\"level\""), std::string::npos) << "older configs' text (and cache keys) unchanged";
  c.robot->gait.level = 0.75;
  EXPECT_EQ(SimConfigFromJson(SimConfigToJson(c), "round trip").robot->gait.level, 0.75);
  const std::string text = SimConfigToJson(c);
  const std::string over = std::regex_replace(text, std::regex("\"level\": ?0.75"), "\"level\": 1.5");
  ASSERT_NE(over, text);
  try {
    SimConfigFromJson(over, "c.json");
    ADD_FAILURE() << "a level above 1 was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("robot.gait.level"), std::string::npos) << e.what();
  }
}

// The hexapod modelled facing +y: every leg's mount turned 90 degrees about the torso's z (position
// and yaw) and the torso box turned with it, robot.forward_axis [0, 1, 0]. Each (command, placement)
// must do what it does on the hexapod facing +x: the same physics seen from a turned torso frame.
SimConfig HexapodFacingY(const fs::path& path) {
  std::string xml = ReadText(kRobots / "hexapod.xml");
  const std::regex mount(R"re(_coxa" pos="([-0-9.]+) ([-0-9.]+) 0" euler="0 0 ([-0-9.]+)")re");
  std::string turned;
  auto from = xml.cbegin();
  int legs = 0;
  for (std::sregex_iterator it(xml.begin(), xml.end(), mount), end; it != end; ++it, ++legs) {
    const std::smatch& m = *it;
    turned.append(from, m[0].first);
    char text[120];
    std::snprintf(text, sizeof text, "_coxa\" pos=\"%g %g 0\" euler=\"0 0 %g\"", -std::stod(m[2]), std::stod(m[1]),
                  std::stod(m[3]) + 90);
    turned += text;
    from = m[0].second;
  }
  turned.append(from, xml.cend());
  EXPECT_EQ(legs, 6);
  const std::string box = "size=\"0.15 0.075 0.025\"";
  turned.replace(turned.find(box), box.size(), "size=\"0.075 0.15 0.025\"");
  std::ofstream(path) << turned;
  SimConfig c = Hexapod();
  c.mjcf_path = path.string();
  c.robot->forward_axis = Eigen::Vector3d::UnitY();
  return c;
}

// Travel (robot frame: forward, left) and yaw of one command from a placement at the origin.
Eigen::Vector3d Travel(Simulator& sim, const Eigen::Vector3d& command) {
  EXPECT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  EXPECT_EQ(sim.RunCommand(command), RunOutcome::kCompleted);
  const Eigen::Vector3d moved = start.rotation.transpose() * (sim.TorsoPose().position_m - start.position_m);
  const Eigen::Matrix3d turn = start.rotation.transpose() * sim.TorsoPose().rotation;
  return Eigen::Vector3d(moved.x(), moved.y(), std::atan2(turn(1, 0), turn(0, 0)));
}

// Half a forward command travels within 25% of half the stride and straight (sideways under
// 15% of it); half a turn turns the commanded way within 30%.
void ExpectWalksAsCommanded(Simulator& sim) {
  const RobotDescription& r = *sim.config().robot;
  const double cycles = sim.config().command_duration_s / r.gait.period_s;
  const double stride = r.gait.stride_reach * sim.leg_reach_m() * cycles;
  const Eigen::Vector3d forward = Travel(sim, Eigen::Vector3d(0.5, 0, 0));
  EXPECT_NEAR(forward.x() / (0.5 * stride), 1.0, 0.25);
  EXPECT_LT(std::abs(forward.y()) / (0.5 * stride), 0.15);
  const Eigen::Vector3d turn = Travel(sim, Eigen::Vector3d(0, 0, -0.5));
  EXPECT_NEAR(turn.z() / (-0.5 * r.gait.turn_rad * cycles), 1.0, 0.3);
}

TEST(LeggedRobot, TheForwardAxisTurnsTheRobotsFrame) {
  const fs::path path = fs::temp_directory_path() / ("dgmm_facing_y_" + std::to_string(::getpid()) + ".xml");
  Simulator facing_x(Hexapod()), facing_y(HexapodFacingY(path));
  fs::remove(path);
  EXPECT_NEAR(facing_y.leg_reach_m(), facing_x.leg_reach_m(), 1e-9);
  for (const Eigen::Vector3d& command : {Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(0, -0.5, 0),
                                         Eigen::Vector3d(0, 0, 0.5)}) {
    const Eigen::Vector3d x = Travel(facing_x, command), y = Travel(facing_y, command);
    EXPECT_LT((y.head<2>() - x.head<2>()).norm(), 0.01) << "command " << command.transpose() << ": " << y.transpose()
                                                         << " facing +y, " << x.transpose() << " facing +x";
    EXPECT_NEAR(y.z(), x.z(), 0.02) << "command " << command.transpose();
  }
}

// The torso's height at release (no settling) with every foot given as the hexapod's foot geoms,
// as sites at those geoms' centres, or as the tibia bodies with the centres as offsets.
double ReleaseHeight(const std::string& foot_kind) {
  std::string xml = ReadText(kRobots / "hexapod.xml");
  const std::string centre = "0.03 0 -0.16";  // every foot geom's centre in its tibia's frame
  SimConfig c = Hexapod();
  for (auto& leg : c.robot->legs) {
    const std::string geom = leg.foot.geom, at = "<geom name=\"" + geom + "\"";
    if (foot_kind == "site") {
      xml.insert(xml.find(at), "<site name=\"" + leg.name + "_tip\" pos=\"" + centre + "\"/>");
      leg.foot = {};
      leg.foot.site = leg.name + "_tip";
    } else if (foot_kind == "body") {
      leg.foot = {};
      leg.foot.body = leg.name + "_tibia";
      leg.foot.offset_m = Eigen::Vector3d(0.03, 0, -0.16);
    }
  }
  const fs::path path = fs::temp_directory_path() / ("dgmm_feet_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  c.mjcf_path = path.string();
  c.settle_duration_s = 0;
  Simulator sim(c);
  fs::remove(path);
  EXPECT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  return sim.TorsoPose().position_m.z();
}

// A site or body foot has no shape of its own: its contact reach below the foot point is the
// colliding geoms' on its body (the capsules and boxes 1 cm and 0.8 cm below the centres). Until
// 2026-12-03 it was taken as 0 and such a robot was released with its feet 1 cm in the ground.
TEST(LeggedRobot, SiteAndBodyFeetArePlacedAsTheirGeomsAre) {
  const double geom = ReleaseHeight("geom");
  EXPECT_NEAR(ReleaseHeight("site"), geom, 1e-9);
  EXPECT_NEAR(ReleaseHeight("body"), geom, 1e-9);
}

TEST(LeggedRobot, TheModelsOwnPhysicsIsKeptExceptWhatTheExperimentSets) {
  const SimConfig c = Hexapod(10);
  MjModelPtr original = LoadRobotModel(c);
  MjModelPtr applied = LoadRobotModel(c);
  const LeggedRobot bound = BindRobot(applied.get(), *c.robot, "hexapod");
  SimConfig experiment = c;
  experiment.timestep_s = 0.001;
  ApplyExperiment(experiment, bound, applied.get());
  const mjModel* a = original.get();
  const mjModel* b = applied.get();
  auto same = [](const mjtNum* x, const mjtNum* y, int n) { return std::memcmp(x, y, sizeof(mjtNum) * n) == 0; };
  EXPECT_TRUE(same(a->body_mass, b->body_mass, a->nbody));
  EXPECT_TRUE(same(a->body_inertia, b->body_inertia, 3 * a->nbody));
  EXPECT_TRUE(same(a->geom_friction, b->geom_friction, 3 * a->ngeom));
  EXPECT_TRUE(same(a->geom_solref, b->geom_solref, mjNREF * a->ngeom));
  EXPECT_TRUE(same(a->dof_damping, b->dof_damping, a->nv));
  EXPECT_TRUE(same(a->dof_armature, b->dof_armature, a->nv));
  EXPECT_TRUE(same(a->actuator_gainprm, b->actuator_gainprm, mjNGAIN * a->nu));
  EXPECT_TRUE(same(a->actuator_biasprm, b->actuator_biasprm, mjNBIAS * a->nu));
  EXPECT_TRUE(same(a->actuator_forcerange, b->actuator_forcerange, 2 * a->nu));
  EXPECT_TRUE(same(a->jnt_range, b->jnt_range, 2 * a->njnt));
  EXPECT_EQ(b->opt.timestep, 0.001);
  EXPECT_NEAR(std::hypot(b->opt.gravity[0], b->opt.gravity[2]), std::abs(a->opt.gravity[2]), 1e-12);
  EXPECT_NEAR(std::atan2(-b->opt.gravity[0], -b->opt.gravity[2]) * 180 / M_PI, 10, 1e-9);
}

TEST(LeggedRobot, ALegGainScalesThatLegsServosOnly) {
  SimConfig c = Hexapod();
  c.robot->leg_gain["middle_right"] = 0.5;
  MjModelPtr m = LoadRobotModel(c);
  MjModelPtr original = LoadRobotModel(c);
  const LeggedRobot bound = BindRobot(m.get(), *c.robot, "hexapod");
  ApplyExperiment(c, bound, m.get());
  for (const auto& leg : bound.legs) {
    for (int a : leg.actuators) {
      const double ratio = m->actuator_gainprm[mjNGAIN * a] / original->actuator_gainprm[mjNGAIN * a];
      EXPECT_DOUBLE_EQ(ratio, leg.name == "middle_right" ? 0.5 : 1.0) << leg.name;
    }
  }
}

// A payload merges into the torso: total mass, centre of mass, and an inertia tensor that adds the
// parallel-axis terms (products of inertia too: the payload is off every axis) plus the payload's
// own, a ball of radius 0.1 x the robot's reach (so the block scales with the robot instead of
// being 3 cm for every robot), its principal axes the torso's new inertial frame.
TEST(LeggedRobot, APayloadMergesIntoTheTorsoAtTheRobotsScale) {
  using Matrix3 = Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>;
  SimConfig c = Hexapod();
  c.payload.mass_kg = 0.8;
  c.payload.position_body_m = Eigen::Vector3d(0.05, -0.02, 0.01);
  MjModelPtr m = LoadRobotModel(c);
  MjModelPtr original = LoadRobotModel(c);
  const LeggedRobot bound = BindRobot(m.get(), *c.robot, "hexapod");
  ApplyExperiment(c, bound, m.get());
  const int t = bound.torso_body;
  const double m0 = original->body_mass[t], mass = 0.8;
  EXPECT_DOUBLE_EQ(m->body_mass[t], m0 + mass);
  const Eigen::Vector3d c0(original->body_ipos + 3 * t), p = bound.robot_in_torso * c.payload.position_body_m;
  const Eigen::Vector3d centre = (m0 * c0 + mass * p) / (m0 + mass);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m->body_ipos[3 * t + k], centre[k], 1e-12);
  auto tensor = [](const mjModel* model, int body) {  // in the body's frame
    Matrix3 r;
    mju_quat2Mat(r.data(), model->body_iquat + 4 * body);
    return Matrix3(r * Eigen::Vector3d(model->body_inertia + 3 * body).asDiagonal() * r.transpose());
  };
  auto moved = [](double kg, const Eigen::Vector3d& d) {
    return Matrix3(kg * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose()));
  };
  const double radius = 0.1 * bound.reach_m;
  const Matrix3 want = tensor(original.get(), t) + moved(m0, c0 - centre) + moved(mass, p - centre) +
                       0.4 * mass * radius * radius * Matrix3::Identity();
  // mju_eig3 stops turning the axes below 1.4e-6 rad: agreement to about 1e-6 of the tensor's size.
  EXPECT_LT((tensor(m.get(), t) - want).cwiseAbs().maxCoeff(), 2e-6 * want.cwiseAbs().maxCoeff()) << want;
  EXPECT_GT(std::fabs(want(0, 1)), 1e-4);  // products of inertia the old per-axis sum left out
  for (int b = 0; b < m->nbody; ++b) {
    if (b != t) EXPECT_EQ(m->body_mass[b], original->body_mass[b]) << "body " << b;
  }
}

// MuJoCo copies the body's own frame for a body compiled with its centre of mass at its origin
// (the hexapod's torso: one box), and copies the centre for a geom compiled there (the torso's box
// moved up 1 cm): a payload must move the centre MuJoCo simulates, not only body_ipos, and leave
// the geoms where they are on the torso. Before 2026-12-05 a payload 3 cm ahead and 3 cm behind
// the hexapod's middle gave the same recording to the last bit.
TEST(LeggedRobot, APayloadMovesTheCentreOfMassMuJoCoSimulatesAndNoGeom) {
  for (const std::string moved_box : {"", " pos=\"0 0 0.01\""}) {
    std::string xml = ReadText(kRobots / "hexapod.xml");
    const std::string box = "<geom name=\"torso\" type=\"box\"";
    ASSERT_NE(xml.find(box), std::string::npos);
    xml.insert(xml.find(box) + box.size(), moved_box);
    const fs::path path = fs::temp_directory_path() / ("dgmm_payload_" + std::to_string(::getpid()) + ".xml");
    std::ofstream(path) << xml;
    SimConfig c = Hexapod();
    c.mjcf_path = path.string();
    c.payload.mass_kg = 0.8;
    c.payload.position_body_m = Eigen::Vector3d(0.05, -0.02, 0.01);
    MjModelPtr m = LoadRobotModel(c), original = LoadRobotModel(c);
    fs::remove(path);
    const LeggedRobot bound = BindRobot(m.get(), *c.robot, "hexapod");
    const int t = bound.torso_body, g = mj_name2id(m.get(), mjOBJ_GEOM, "torso");
    ASSERT_EQ(original->body_sameframe[t], moved_box.empty() ? 1 : 0);
    ASSERT_EQ(original->geom_sameframe[g], moved_box.empty() ? 1 : 2);
    ApplyExperiment(c, bound, m.get());
    MjDataPtr d(mj_makeData(m.get())), d0(mj_makeData(original.get()));
    d->qpos[3] = d0->qpos[3] = std::cos(0.2);  // the torso turned 0.4 rad about z: frames told apart
    d->qpos[6] = d0->qpos[6] = std::sin(0.2);
    mj_forward(m.get(), d.get());
    mj_forward(original.get(), d0.get());
    const Eigen::Map<const Eigen::Matrix3d> torso_rotation(d->xmat + 9 * t);  // row-major: transpose
    const Eigen::Vector3d centre(m->body_ipos + 3 * t);
    const Eigen::Vector3d simulated = Eigen::Vector3d(d->xipos + 3 * t) - Eigen::Vector3d(d->xpos + 3 * t);
    EXPECT_LT((simulated - torso_rotation.transpose() * centre).norm(), 1e-12) << moved_box;
    EXPECT_GT(centre.norm(), 0.005) << moved_box;
    EXPECT_LT((Eigen::Vector3d(d->geom_xpos + 3 * g) - Eigen::Vector3d(d0->geom_xpos + 3 * g)).norm(), 1e-12)
        << moved_box;
  }
}

// The merged payload is the rigid body MuJoCo would simulate: the sprawled quadruped's torso has
// its principal axes turned (its compiled body_iquat is not the unit quaternion) and a payload off
// every axis adds products of inertia; the torso's composite inertia (mj_crb: mass, centre and the
// full tensor of it and everything below it) equals that of the same robot with the payload as a
// body of its own welded to the torso.
TEST(LeggedRobot, AMergedPayloadHasTheInertiaOfTheSameBallWeldedOn) {
  const Eigen::Vector3d at(0.05, -0.02, 0.01);
  const double kg = 0.8;
  SimConfig c = LoadSimConfig((kRobots / "sprawled_quadruped.json").string());
  c.payload.mass_kg = kg;
  c.payload.position_body_m = at;
  MjModelPtr merged = LoadRobotModel(c);
  const LeggedRobot bound = BindRobot(merged.get(), *c.robot, "sprawled_quadruped");
  const int t = bound.torso_body;
  ASSERT_LT(std::fabs(merged->body_iquat[4 * t]), 0.999);  // turned: not the unit quaternion
  ApplyExperiment(c, bound, merged.get());

  std::string xml = ReadText(kRobots / "sprawled_quadruped.xml");
  const std::string torso = "<body name=\"body\" pos=\"0 0 0.25\">";
  ASSERT_NE(xml.find(torso), std::string::npos);
  const Eigen::Vector3d p = bound.robot_in_torso * at;
  const double ball = 0.4 * kg * std::pow(0.1 * bound.reach_m, 2);
  std::ostringstream welded;
  welded << std::setprecision(17) << "<body name=\"welded_payload\" pos=\"" << p.x() << " " << p.y() << " " << p.z()
         << "\"><inertial pos=\"0 0 0\" mass=\"" << kg << "\" diaginertia=\"" << ball << " " << ball << " " << ball
         << "\"/></body>";
  xml.insert(xml.find(torso) + torso.size(), welded.str());
  const fs::path path = fs::temp_directory_path() / ("dgmm_welded_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  char error[1000] = "";
  MjModelPtr reference(mj_loadXML(path.string().c_str(), nullptr, error, sizeof error));
  fs::remove(path);
  ASSERT_TRUE(reference) << error;
  ASSERT_EQ(reference->nq, merged->nq);
  ASSERT_EQ(mj_name2id(reference.get(), mjOBJ_BODY, "body"), t);

  MjDataPtr d(mj_makeData(merged.get())), r(mj_makeData(reference.get()));
  for (int i = 0; i < merged->nq; ++i) d->qpos[i] = r->qpos[i] = reference->qpos0[i];
  d->qpos[3] = r->qpos[3] = std::cos(0.2);  // the torso turned 0.4 rad about z
  d->qpos[6] = r->qpos[6] = std::sin(0.2);
  mj_forward(merged.get(), d.get());
  mj_forward(reference.get(), r.get());
  // crb: the tensor (xx, yy, zz, xy, xz, yz), mass times centre, mass. mju_eig3 stops turning the
  // axes below 1.4e-6 rad (1 - cos under 1e-12), so the tensor agrees to about 1e-6 of its size;
  // the old per-axis sum missed the products of inertia by 8e-4 kg m^2 here.
  const double size = Eigen::Vector3d(r->crb + 10 * t).cwiseAbs().maxCoeff();
  for (int k = 0; k < 10; ++k) {
    const double tolerance = k < 6 ? 2e-6 * size : 1e-12 * (1 + std::fabs(r->crb[10 * t + k]));
    EXPECT_NEAR(d->crb[10 * t + k], r->crb[10 * t + k], tolerance) << "crb " << k;
  }
}

// A payload is bounded by the robot's own scale, not by metres and kilograms fixed for one robot:
// the hexapod (3.2 kg, reach 0.30 m) refuses 40 kg and an offset of 0.7 m; a 1.5 m offset is
// accepted from a config without a robot block only up to 1 m.
TEST(LeggedRobot, APayloadIsBoundedByTheRobotsMassAndReach) {
  auto error_of = [](double kg, const Eigen::Vector3d& at) {
    SimConfig c = Hexapod();
    c.payload.mass_kg = kg;
    c.payload.position_body_m = at;
    try {
      Simulator sim(c);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of(3.0, Eigen::Vector3d(0.3, 0, 0)), "");
  EXPECT_NE(error_of(40, Eigen::Vector3d::Zero()).find("payload.mass_kg: 40 kg is over 10 times the robot's mass"),
            std::string::npos);
  EXPECT_NE(error_of(1, Eigen::Vector3d(0.7, 0, 0)).find("payload.position_body_m: 0.7 m from the torso"),
            std::string::npos);
  SimConfig big = Hexapod();
  big.payload.mass_kg = 150;  // over the built-in robot's fixed 100 kg, checked only against this robot
  std::string error;
  EXPECT_TRUE(big.IsValid(&error)) << error;
  big.robot.reset();
  EXPECT_FALSE(big.IsValid(&error));
}

// The gait's targets are solved at least 60 times a cycle and at 100 Hz at the least: the hexapod
// (0.6 s, 2 ms steps) and the slower robots every 5 steps as before; a 0.5 s cycle every 4; a
// robot a quarter of the hexapod's size (0.3 s cycle, 1 ms steps) every 5 steps, as the hexapod's
// 60 a cycle, not 10; a step longer than that, every step.
TEST(LeggedRobot, TheGaitIsSolvedOftenEnoughForItsCycle) {
  for (double period : {0.6, 0.8}) EXPECT_EQ(ControlEvery(period, 0.002), 5) << period;
  EXPECT_EQ(ControlEvery(0.5, 0.002), 4);
  EXPECT_EQ(ControlEvery(1.2, 0.004), 3);   // four times the hexapod's size: its 100 Hz
  EXPECT_EQ(ControlEvery(0.3, 0.001), 5);
  EXPECT_EQ(ControlEvery(0.05, 0.002), 1);
}

// Placements span 2.5 leg reaches of a robot block's robot (1 m for the built-in one) unless the
// config gives a width; on terrain, a width that leaves under 2 reaches to the edge is warned about.
TEST(LeggedRobot, PlacementsSpanTheRobotsReach) {
  SimConfig c = Hexapod();
  {
    Simulator sim(c);
    EXPECT_NEAR(sim.placement_half_width_m(), 2.5 * sim.leg_reach_m(), 1e-12);
  }
  c.placement_half_width_m = 0.4;
  EXPECT_DOUBLE_EQ(Simulator(c).placement_half_width_m(), 0.4);
  c.terrain = TerrainDescription{};
  c.terrain->half_size_m = 0.9;
  bool warned = false;
  for (const std::string& w : Simulator(c).RobotWarnings()) warned |= w.find("placement_half_width_m") != std::string::npos;
  EXPECT_TRUE(warned);
  c.terrain->half_size_m = 1.2;
  for (const std::string& w : Simulator(c).RobotWarnings()) EXPECT_EQ(w.find("placement_half_width_m"), std::string::npos) << w;
  SimConfig builtin;
  EXPECT_DOUBLE_EQ(Simulator(builtin).placement_half_width_m(), 1.0);
  builtin.placement_half_width_m = -1;
  std::string error;
  EXPECT_FALSE(builtin.IsValid(&error));
  EXPECT_NE(error.find("placement_half_width_m"), std::string::npos);
}

TEST(LeggedRobot, FootExtentForCapsuleAndBoxFeet) {
  const SimConfig c = Hexapod();
  MjModelPtr m = LoadRobotModel(c);
  const LeggedRobot bound = BindRobot(m.get(), *c.robot, "hexapod");
  for (const auto& leg : bound.legs) {
    // Capsule feet lie horizontally (radius 0.01 m); box feet are 0.008 m half-high.
    const double expected = leg.name.rfind("middle", 0) == 0 ? 0.008 : 0.01;
    EXPECT_NEAR(leg.foot_extent_m, expected, 1e-3) << leg.name;
  }
  EXPECT_NEAR(bound.reach_m, 0.297, 0.01);
}

// A mesh foot reaches below its centre as far as its lowest vertex, not its bounding sphere: the
// hexapod's middle box feet (0.032 x 0.032 x 0.016 m) given as meshes of the same box reach 0.008 m
// (the bounding sphere's 0.024 m was used until 2026-12-03: the robot was released 1.6 cm high).
TEST(LeggedRobot, AMeshFootReachesAsFarAsItsLowestVertex) {
  std::string xml = ReadText(kRobots / "hexapod.xml");
  const std::string box = R"(type="box" pos="0.03 0 -0.16" size="0.016 0.016 0.008")";
  for (auto at = xml.find(box); at != std::string::npos; at = xml.find(box, at)) {
    xml.replace(at, box.size(), R"(type="mesh" mesh="pad" pos="0.03 0 -0.16")");
  }
  const auto head = xml.find("<worldbody>");
  xml.insert(head, R"(<asset><mesh name="pad" vertex="-0.016 -0.016 -0.008  0.016 -0.016 -0.008  0.016 0.016 -0.008
    -0.016 0.016 -0.008  -0.016 -0.016 0.008  0.016 -0.016 0.008  0.016 0.016 0.008  -0.016 0.016 0.008"/></asset>)");
  const fs::path path = fs::temp_directory_path() / ("dgmm_mesh_feet_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig c = Hexapod();
  c.mjcf_path = path.string();
  MjModelPtr m = LoadRobotModel(c);
  fs::remove(path);
  const LeggedRobot bound = BindRobot(m.get(), *c.robot, "hexapod with mesh feet");
  int meshes = 0;
  for (const auto& leg : bound.legs) {
    if (m->geom_type[leg.foot_geom] != mjGEOM_MESH) continue;
    ++meshes;
    EXPECT_NEAR(leg.foot_extent_m, 0.008, 1e-6) << leg.name;
  }
  EXPECT_EQ(meshes, 2);
}

TEST(LeggedRobot, BadRobotsAreRefusedNamingThePart) {
  auto expect = [](const std::string& error, const std::string& part) {
    EXPECT_NE(error.find(part), std::string::npos) << "expected \"" << part << "\" in: " << error;
  };
  // An undriven joint not declared passive, e.g. a ninth joint on a leg or extra legs.
  expect(ErrorOf("<geom name=\"rear_right_foot\"",
                 "<body name=\"ankle\"><joint name=\"extra\" type=\"hinge\" axis=\"0 1 0\" range=\"-10 10\"/>"
                 "<geom type=\"sphere\" size=\"0.005\" mass=\"0.01\"/></body><geom name=\"rear_right_foot\""),
         "joint \"extra\" belongs to no leg");
  // ...accepted once declared passive.
  EXPECT_EQ(ErrorOf("<geom name=\"rear_right_foot\"",
                    "<body name=\"ankle\"><joint name=\"extra\" type=\"hinge\" axis=\"0 1 0\" range=\"-10 10\"/>"
                    "<geom type=\"sphere\" size=\"0.005\" mass=\"0.01\"/></body><geom name=\"rear_right_foot\"",
                    [](RobotDescription* r) { r->passive_joints.push_back("extra"); }),
            "");
  // An actuator driving nothing a leg declares.
  expect(ErrorOf("", "", [](RobotDescription* r) { r->legs.pop_back(); r->gait.pattern = "custom";
                                                   r->gait.phases = {0, 0.2, 0.4, 0.6, 0.8}; }),
         "belongs to no leg");
  // A motor instead of a position servo.
  expect(ErrorOf("<position name=\"front_left_knee\" joint=\"front_left_knee\"/>",
                 "<motor name=\"front_left_knee\" joint=\"front_left_knee\"/>"),
         "not a position servo");
  // A joint off the leg's chain.
  expect(ErrorOf("", "", [](RobotDescription* r) { r->legs[0].joints[2] = "front_right_knee"; }),
         "robot.legs[0] (front_left).joints");
  // A declared side contradicting the geometry.
  expect(ErrorOf("", "", [](RobotDescription* r) { r->legs[1].side = "right"; }), "robot.legs[1] (middle_left).side");
  // A foot that cannot reach the ground at the stance height (a short leg).
  expect(ErrorOf("", "", [](RobotDescription* r) { r->gait.stance_height_m = 0.5; }), "cannot reach the ground");
  // A missing foot.
  expect(ErrorOf("", "", [](RobotDescription* r) { r->legs[2].foot.geom = "no_such_foot"; }),
         "robot.legs[2] (rear_left).foot.geom");
  // A foot whose body has no geom that can touch the floor (visual geoms only).
  expect(ErrorOf(R"(<geom type="capsule" fromto="0 0 0 0.03 0 -0.15" size="0.01" mass="0.05" rgba="0.5 0.5 0.55 1"/>
            <geom name="front_left_foot" type="capsule")",
                 R"(<geom type="capsule" fromto="0 0 0 0.03 0 -0.15" size="0.01" mass="0.05" contype="0" conaffinity="0"/>
            <geom name="front_left_foot" contype="0" conaffinity="0" type="capsule")"),
         "robot.legs[0] (front_left).foot: no geom of body \"front_left_tibia\" or below it can touch the floor");
  // A gait for another number of legs.
  expect(ErrorOf("", "", [](RobotDescription* r) { r->gait.pattern = "trot"; }), "needs 4 legs");
}

// The planar quadruped (datasets/robots/planar_quadruped.json) with its knees' range `range` and
// `extra` before the model's end (e.g. a keyframe), written to a temporary MJCF.
SimConfig PlanarWithKneeRange(const std::string& range, const std::string& extra = "") {
  std::string xml = ReadText(kRobots / "planar_quadruped.xml");
  for (auto at = xml.find("range=\"-10 120\""); at != std::string::npos; at = xml.find("range=\"-10 120\"", at)) {
    xml.replace(at, 15, "range=\"" + range + "\"");
  }
  xml.insert(xml.rfind("</mujoco>"), extra);
  const fs::path path = fs::temp_directory_path() / ("dgmm_planar_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << xml;
  SimConfig c = LoadSimConfig((kRobots / "planar_quadruped.json").string());
  c.mjcf_path = path.string();
  return c;
}

// Knees that bend the other way (range -120 to 10 degrees): from the rest pose, straight legs,
// damped least squares pushes each knee into its 10 degree limit and the hip to -60 (0.195 m off),
// and the robot was refused as if its feet could not reach the ground. Other starts find the stance.
TEST(LeggedRobot, TheStanceIsFoundWhenTheRestPoseLeadsAJointIntoItsLimit) {
  const SimConfig c = PlanarWithKneeRange("-120 10");
  std::unique_ptr<Simulator> sim;
  ASSERT_NO_THROW(sim = std::make_unique<Simulator>(c));
  fs::remove(c.mjcf_path);
  ASSERT_EQ(sim->Place(0, 0, 0), RunOutcome::kCompleted);
  for (const Eigen::Vector3d& foot : sim->FootPositions()) EXPECT_LT(foot.z(), 0.03);  // on the ground
  EXPECT_GT(sim->TorsoPose().position_m.z(), 0.15);  // standing on them: the stance height is 0.2 m
}

// A model whose joints at zero lie outside their ranges (knees from 20 to 120 degrees) and whose
// standing pose is its first keyframe (knees at 60 degrees), as public quadruped models are
// written: the rest pose, the stance height and the reach come from the keyframe. Standing on
// straighter legs than the keyframe's would put the torso higher.
TEST(LeggedRobot, TheFirstKeyframeIsTheRestPose) {
  const std::string key = "<keyframe><key qpos='0 0 0.2 1 0 0 0 -0.5 1.05 -0.5 1.05 -0.5 1.05 -0.5 1.05'/></keyframe>";
  const SimConfig with_key = PlanarWithKneeRange("20 120", key);
  Simulator crouched(with_key);
  fs::remove(with_key.mjcf_path);
  const SimConfig without = PlanarWithKneeRange("20 120");
  Simulator upright(without);
  fs::remove(without.mjcf_path);
  EXPECT_NEAR(crouched.leg_reach_m(), upright.leg_reach_m(), 1e-9);  // link by link: the same legs
  ASSERT_EQ(crouched.Place(0, 0, 0), RunOutcome::kCompleted);
  ASSERT_EQ(upright.Place(0, 0, 0), RunOutcome::kCompleted);
  EXPECT_LT(crouched.TorsoPose().position_m.z(), upright.TorsoPose().position_m.z() - 0.02)
      << crouched.TorsoPose().position_m.z() << " m with the keyframe";
}

// Knees that hardly bend (range -1 to 1 degree) cannot lift the feet to the stance height: refused,
// and the message names the joint held at its limit.
TEST(LeggedRobot, AFootThatCannotReachNamesTheJointsAtTheirLimits) {
  const SimConfig c = PlanarWithKneeRange("-1 1");
  std::string error;
  try {
    Simulator sim(c);
  } catch (const std::exception& e) {
    error = e.what();
  }
  fs::remove(c.mjcf_path);
  EXPECT_NE(error.find("robot.legs[0] (fl): the foot cannot reach the ground"), std::string::npos) << error;
  EXPECT_NE(error.find("at their range limits: fl_knee"), std::string::npos) << error;
}

TEST(LeggedRobot, TheSprawledQuadrupedTrotsOnItsPassiveAnkles) {
  Simulator sim(LoadSimConfig((kRobots / "sprawled_quadruped.json").string()));
  const RobotDescription& r = *sim.config().robot;
  ASSERT_EQ(sim.leg_count(), 4);
  EXPECT_EQ(r.passive_joints.size(), 4u);
  const double cycles = sim.config().command_duration_s / r.gait.period_s;
  const double stride = r.gait.stride_reach * sim.leg_reach_m() * cycles;
  ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
  const Pose start = sim.TorsoPose();
  ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0.5, 0, 0)), RunOutcome::kCompleted);
  const Eigen::Vector3d moved = start.rotation.transpose() * (sim.TorsoPose().position_m - start.position_m);
  EXPECT_NEAR(moved.x() / (0.5 * stride), 1.0, 0.25);
  EXPECT_LT(std::abs(moved.y()) / (0.5 * stride), 0.15);
}

// The crawl (one foot in the air at a time, duty 0.75): with the feet at the corners of a flat body
// the centre of mass lies on the diagonal of the three feet that stay down, so without a sway the
// body tips onto the lifted hind foot, which drags (about half the stride); the default sway
// (robot.gait.sway) walks it within 25% of the command, upright.
TEST(LeggedRobot, TheSprawledQuadrupedCrawlsWhenItSwaysItsBody) {
  for (const double sway : {-1.0, 0.0}) {  // the default, then none
    SimConfig config = LoadSimConfig((kRobots / "sprawled_quadruped.json").string());
    config.robot->gait.pattern = "crawl";
    config.robot->gait.sway = sway;
    Simulator sim(config);
    const RobotDescription& r = *sim.config().robot;
    const double stride = r.gait.stride_reach * sim.leg_reach_m() * sim.config().command_duration_s / r.gait.period_s;
    ASSERT_EQ(sim.Place(0, 0, 0), RunOutcome::kCompleted);
    const Pose start = sim.TorsoPose();
    const double t0 = sim.time_s();
    double worst_tilt = 0;  // degrees between the torso's up axis and its start, after the first cycle
    auto tilt = [&](const Simulator& s) {
      const double cos_tilt = std::min(1.0, s.TorsoPose().rotation.col(2).dot(start.rotation.col(2)));
      if (s.time_s() > t0 + r.gait.period_s) worst_tilt = std::max(worst_tilt, std::acos(cos_tilt) * 180 / M_PI);
    };
    ASSERT_EQ(sim.RunCommand(Eigen::Vector3d(0.5, 0, 0), tilt, 10), RunOutcome::kCompleted);
    const Eigen::Vector3d moved = start.rotation.transpose() * (sim.TorsoPose().position_m - start.position_m);
    if (sway < 0) {
      EXPECT_NEAR(moved.x() / (0.5 * stride), 1.0, 0.25);
      EXPECT_LT(std::abs(moved.y()) / (0.5 * stride), 0.15);
      EXPECT_LT(worst_tilt, 2.5);
    } else {
      EXPECT_LT(moved.x() / (0.5 * stride), 0.75);
      EXPECT_GT(worst_tilt, 4.0);
    }
  }
}

// The hexapod's MJCF without one leg's body (and all below it) and its actuators, written to `path`;
// the config without the leg and with the gait left to auto (as scripts/drop_leg.py makes them).
SimConfig HexapodWithout(const std::string& leg, const fs::path& path) {
  std::string xml = ReadText(kRobots / "hexapod.xml");
  const std::size_t begin = xml.find("<body name=\"" + leg + "_coxa\"");
  std::size_t end = begin;
  for (int depth = 0; end != std::string::npos;) {  // to the body's own closing tag
    const std::size_t open = xml.find("<body", end + 1), close = xml.find("</body>", end + 1);
    if (open < close) {
      ++depth, end = open;
    } else if (depth-- > 0) {
      end = close;
    } else {
      end = close + std::strlen("</body>");
      break;
    }
  }
  EXPECT_NE(begin, std::string::npos);
  xml.erase(begin, end - begin);
  xml = std::regex_replace(xml, std::regex("<position [^>]*joint=\"" + leg + "_[a-z_]+\"/>"), "");
  std::ofstream(path) << xml;
  SimConfig c = Hexapod();
  c.mjcf_path = path.string();
  auto& legs = c.robot->legs;
  legs.erase(std::remove_if(legs.begin(), legs.end(), [&](const LegDescription& l) { return l.name == leg; }),
             legs.end());
  c.robot->gait.pattern = "auto";
  return c;
}

// A hexapod that lost its rear right leg walks in the wave (one foot in the air at a time, the
// pattern auto picks for five legs) as commanded: forward within 25% and straight, turning the
// commanded way within 30%.
TEST(LeggedRobot, AHexapodThatLostALegWalksInTheWave) {
  const fs::path path = fs::temp_directory_path() / ("dgmm_five_legs_" + std::to_string(::getpid()) + ".xml");
  Simulator sim(HexapodWithout("rear_right", path));
  fs::remove(path);
  ASSERT_EQ(sim.leg_count(), 5);
  ExpectWalksAsCommanded(sim);
}

// The centipede (datasets/robots/centipede.json): three body segments in a row, the middle one
// hung from the head by a driven yaw joint (robot.held_joints), the tail by a passive spring.
SimConfig Centipede(double slope_deg = 0) {
  SimConfig c = LoadSimConfig((kRobots / "centipede.json").string());
  c.slope_deg = slope_deg;
  return c;
}

// Its MJCF with `extra` before the model's end, at a temporary path.
SimConfig CentipedeWith(const fs::path& path, const std::string& extra) {
  std::string xml = ReadText(kRobots / "centipede.xml");
  xml.insert(xml.rfind("</mujoco>"), extra);
  std::ofstream(path) << xml;
  SimConfig c = Centipede();
  c.mjcf_path = path.string();
  return c;
}

// Twelve legs on three segments walk as commanded on flat ground and on its 10 degree slope:
// forward within 25% and straight (cross-talk under 15%), turning the commanded way within 30%.
TEST(LeggedRobot, TheCentipedeWalksOnItsSegmentedBody) {
  for (const double slope : {0.0, 10.0}) {
    SCOPED_TRACE(slope);
    Simulator sim(Centipede(slope));
    ASSERT_EQ(sim.leg_count(), 12);
    ExpectWalksAsCommanded(sim);
  }
}

// A held joint is held at its rest value: with a keyframe that bends spine1 by 0.1 rad, the
// walking robot keeps it there (within 0.03 rad) and the round trip keeps the declaration. A gait
// that sent nothing to its servo would leave the ctrl at 0 and straighten it.
TEST(LeggedRobot, AHeldJointIsHeldAtItsRestWhileTheRobotWalks) {
  const fs::path path = fs::temp_directory_path() / ("dgmm_bent_centipede_" + std::to_string(::getpid()) + ".xml");
  std::string qpos = "0 0 0.16 1 0 0 0";
  for (int j = 0; j < 38; ++j) qpos += j == 12 ? " 0.1" : " 0";  // seg0's 12 legs' joints, spine1, ...
  const SimConfig c = CentipedeWith(path, "<keyframe><key qpos='" + qpos + "'/></keyframe>");
  const Ground plane(c);
  GenericWalker walker(c, LoadRobotModel(c), plane, "bent centipede");
  fs::remove(path);
  ASSERT_EQ(walker.robot().held_qpos.size(), 1u);
  EXPECT_NEAR(walker.robot().held_q[0], 0.1, 1e-12);
  walker.Start();
  ASSERT_EQ(walker.Place(0, 0, 0), RunOutcome::kCompleted);
  const int spine = walker.robot().held_qpos[0];
  double worst = 0;
  ASSERT_EQ(walker.Run(Eigen::Vector3d(0.5, 0, 0.3),
                       [&](int) { worst = std::max(worst, std::abs(walker.data()->qpos[spine] - 0.1)); }),
            RunOutcome::kCompleted);
  EXPECT_LT(worst, 0.03);
  const RobotDescription back = RobotDescriptionFromJson(RobotDescriptionToJson(*c.robot), "round trip");
  EXPECT_EQ(back.held_joints, std::vector<std::string>{"spine1"});
}

TEST(LeggedRobot, HeldJointsAreCheckedNamingTheJoint) {
  auto error = [](const std::string& from, const std::string& to, auto edit) {
    return ErrorOfRobot("centipede", from, to, edit);
  };
  auto expect = [](const std::string& message, const std::string& part) {
    EXPECT_NE(message.find(part), std::string::npos) << "expected \"" << part << "\" in: " << message;
  };
  auto none = [](RobotDescription*) {};
  expect(error("", "", [](RobotDescription* r) { r->held_joints.clear(); }),
         "robot.legs: joint \"spine1\" belongs to no leg and is declared neither in robot.passive_joints");
  expect(error("", "", [](RobotDescription* r) { r->held_joints = {"spine1", "s0a_left_knee"}; }),
         "robot.held_joints: joint \"s0a_left_knee\" is also a leg's joint");
  expect(error("", "", [](RobotDescription* r) { r->held_joints = {"spine1", "spine2"}; }),
         "robot.held_joints: joint \"spine2\" is also declared passive");
  expect(error("", "", [](RobotDescription* r) { r->held_joints = {"spine1", "no_such_joint"}; }),
         "robot.held_joints: the model has no joint named \"no_such_joint\"");
  expect(error("<position name=\"spine1\" joint=\"spine1\" kp=\"30\"/>", "<motor joint=\"spine1\"/>", none),
         "robot.held_joints: joint \"spine1\" is not driven by a position servo");
  expect(error("<position name=\"spine1\" joint=\"spine1\" kp=\"30\"/>", "", none),
         "robot.held_joints: joint \"spine1\" is driven by no actuator");
  // An actuator without a name is told by its index and joint.
  expect(error("<position name=\"spine1\" joint=\"spine1\" kp=\"30\"/>", "<position joint=\"spine1\" kp=\"30\"/>",
               [](RobotDescription* r) { r->held_joints.clear(), r->passive_joints.push_back("spine1"); }),
         "actuator 36 (unnamed, on joint \"spine1\") drives no leg's joint and no held joint");
}

}  // namespace
}  // namespace dgmm::sim
