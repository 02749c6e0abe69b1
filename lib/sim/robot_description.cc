// JSON (nlohmann) reading and writing of the `robot` block; strict like sim_config.cc.
#include "sim/robot_description.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sim/json_fields.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

using nlohmann::json;

FootDescription ReadFoot(const json& j, const std::string& path, const std::string& source) {
  JsonFields f(j, path, source);
  FootDescription foot;
  f.String("site", &foot.site);
  f.String("geom", &foot.geom);
  f.String("body", &foot.body);
  f.Vector3("offset_m", &foot.offset_m);
  f.Done();
  const int set = !foot.site.empty() + !foot.geom.empty() + !foot.body.empty();
  if (set != 1) f.Fail(path, "expected exactly one of site, geom or body");
  if (foot.body.empty() && !foot.offset_m.isZero()) f.Fail(path + ".offset_m", "only with body");
  return foot;
}

LegDescription ReadLeg(const json& j, const std::string& path, const std::string& source) {
  JsonFields f(j, path, source);
  LegDescription leg;
  f.String("name", &leg.name);
  f.Strings("joints", &leg.joints);
  f.Strings("actuators", &leg.actuators);
  f.String("side", &leg.side);
  const json* foot = f.Find("foot");
  f.Done();
  if (leg.name.empty()) f.Fail(path + ".name", "every leg needs a name");
  if (leg.joints.empty()) f.Fail(path + ".joints", "expected the leg's joints, torso to foot");
  if (!leg.actuators.empty() && leg.actuators.size() != leg.joints.size()) {
    f.Fail(path + ".actuators", "expected one actuator per joint (or none: the one driving each joint)");
  }
  if (!leg.side.empty() && leg.side != "left" && leg.side != "right") f.Fail(path + ".side", "expected left or right");
  if (!foot) f.Fail(path + ".foot", "every leg needs a foot (site, geom or body + offset_m)");
  leg.foot = ReadFoot(*foot, path + ".foot", source);
  return leg;
}

GaitDescription ReadGait(const json& j, const std::string& source) {
  JsonFields f(j, "robot.gait", source);
  GaitDescription g;
  f.String("pattern", &g.pattern);
  if (const json* v = f.Find("phases")) {
    if (!v->is_array()) f.Fail("robot.gait.phases", "expected an array of numbers in [0, 1)");
    for (const auto& p : *v) {
      if (!p.is_number() || p.get<double>() < 0 || p.get<double>() >= 1) {
        f.Fail("robot.gait.phases", "expected an array of numbers in [0, 1)");
      }
      g.phases.push_back(p.get<double>());
    }
  }
  f.Number("duty_factor", &g.duty_factor, 0, 0.95);
  f.Number("period_s", &g.period_s, 0.05, 10);
  f.Number("stride_reach", &g.stride_reach, 0, 3);
  f.Number("stride_m", &g.stride_m, 0, 100);
  f.Number("step_height_reach", &g.step_height_reach, 0, 1);
  f.Number("step_height_m", &g.step_height_m, 0, 100);
  f.Number("stance_height_reach", &g.stance_height_reach, 0, 1);
  f.Number("stance_height_m", &g.stance_height_m, 0, 100);
  f.Number("turn_rad", &g.turn_rad, 0, 3.2);
  f.Number("lean", &g.lean, 0, 1.5);
  f.Number("level", &g.level, 0, 1);
  f.Number("sway", &g.sway, -1, 1);
  f.Bool("servo_feedforward", &g.servo_feedforward);
  f.Done();
  static const std::set<std::string> kPatterns = {"auto", "trot",        "crawl",
                                                  "tripod", "tetrapod", "wave",
                                                  "alternating", "alternating_tetrapod", "custom"};
  if (!kPatterns.count(g.pattern)) {
    f.Fail("robot.gait.pattern",
           "expected auto, trot, crawl, tripod, tetrapod, wave, alternating, alternating_tetrapod or custom");
  }
  if ((g.pattern == "custom") != !g.phases.empty()) f.Fail("robot.gait.phases", "expected exactly with pattern custom");
  return g;
}

ControllerDescription ReadController(const json& j, const std::string& source) {
  JsonFields f(j, "robot.controller", source);
  ControllerDescription c;
  f.String("type", &c.type);
  f.String("signal", &c.signal);
  const json* recordings = f.Find("recordings");
  f.Done();
  if (c.type != "gait" && c.type != "replay") f.Fail("robot.controller.type", "expected gait or replay");
  if (c.signal != "position" && c.signal != "torque") f.Fail("robot.controller.signal", "expected position or torque");
  if (!c.replay()) {
    if (recordings) f.Fail("robot.controller.recordings", "only with type replay");
    return c;
  }
  if (!recordings || !recordings->is_array() || recordings->empty()) {
    f.Fail("robot.controller.recordings", "expected an array of {\"command\": [long, lat, turn], \"file\": CSV}");
  }
  for (std::size_t i = 0; i < recordings->size(); ++i) {
    const std::string path = "robot.controller.recordings[" + std::to_string(i) + "]";
    JsonFields r((*recordings)[i], path, source);
    ReplayRecording rec;
    rec.command = Eigen::Vector3d::Constant(std::nan(""));
    r.Vector3("command", &rec.command);
    r.String("file", &rec.file);
    r.Done();
    if (!rec.command.allFinite()) r.Fail(path + ".command", "expected [long, lat, turn]");
    if (rec.file.empty()) r.Fail(path + ".file", "expected the recording's CSV file");
    for (const auto& other : c.recordings) {
      if ((other.command - rec.command).norm() < 1e-9) r.Fail(path + ".command", "a second recording of this command");
    }
    c.recordings.push_back(rec);
  }
  return c;
}

}  // namespace

RobotDescription RobotDescriptionFromJson(const std::string& json_text, const std::string& source) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {
    throw MakeInputError(source, "robot", std::string("not valid JSON: ") + e.what());
  }
  JsonFields f(root, "robot", source);
  RobotDescription r;
  f.String("torso_body", &r.torso_body);
  f.String("floor_geom", &r.floor_geom);
  f.Vector3("forward_axis", &r.forward_axis);
  f.Strings("passive_joints", &r.passive_joints);
  f.Strings("held_joints", &r.held_joints);
  f.Bool("overwrite_physics", &r.overwrite_physics);
  const json* legs = f.Find("legs");
  const json* gait = f.Find("gait");
  const json* gains = f.Find("leg_gain");
  const json* controller = f.Find("controller");
  f.Done();
  if (r.forward_axis.norm() < 1e-9 || std::abs(r.forward_axis.z()) > 1e-9) {
    f.Fail("robot.forward_axis", "expected a non-zero horizontal direction in the torso frame (z = 0)");
  }
  r.forward_axis.normalize();
  if (!legs || !legs->is_array() || legs->empty()) f.Fail("robot.legs", "expected an array of legs");
  std::set<std::string> names;
  for (std::size_t i = 0; i < legs->size(); ++i) {
    r.legs.push_back(ReadLeg((*legs)[i], "robot.legs[" + std::to_string(i) + "]", source));
    if (!names.insert(r.legs.back().name).second) {
      f.Fail("robot.legs[" + std::to_string(i) + "].name", "duplicate leg name \"" + r.legs.back().name + "\"");
    }
  }
  if (gait) r.gait = ReadGait(*gait, source);
  if (controller) r.controller = ReadController(*controller, source);
  if (r.gait.servo_feedforward && r.controller.replay()) {
    f.Fail("robot.gait.servo_feedforward",
           "the generic gait's option: a replay sends its recorded signals as they are (remove it, or the replay)");
  }
  if (gains) {
    JsonFields g(*gains, "robot.leg_gain", source);
    for (const auto& [leg, value] : gains->items()) {
      if (!names.count(leg)) g.Fail("robot.leg_gain." + leg, "no leg has this name");
      double v = 1;
      g.Number(leg.c_str(), &v, 0, 10);
      r.leg_gain[leg] = v;
    }
  }
  return r;
}

std::string RobotDescriptionToJson(const RobotDescription& r) {
  json legs = json::array();
  for (const auto& leg : r.legs) {
    json foot;
    if (!leg.foot.site.empty()) foot["site"] = leg.foot.site;
    if (!leg.foot.geom.empty()) foot["geom"] = leg.foot.geom;
    if (!leg.foot.body.empty()) {
      foot["body"] = leg.foot.body;
      foot["offset_m"] = {leg.foot.offset_m.x(), leg.foot.offset_m.y(), leg.foot.offset_m.z()};
    }
    json l = {{"name", leg.name}, {"joints", leg.joints}, {"foot", foot}};
    if (!leg.actuators.empty()) l["actuators"] = leg.actuators;
    if (!leg.side.empty()) l["side"] = leg.side;
    legs.push_back(l);
  }
  const auto& g = r.gait;
  json gait = {{"pattern", g.pattern},         {"duty_factor", g.duty_factor},
               {"period_s", g.period_s},       {"stride_reach", g.stride_reach},
               {"stride_m", g.stride_m},       {"step_height_reach", g.step_height_reach},
               {"step_height_m", g.step_height_m}, {"stance_height_reach", g.stance_height_reach},
               {"stance_height_m", g.stance_height_m}, {"turn_rad", g.turn_rad},
               {"lean", g.lean},               {"sway", g.sway}};
  if (!g.phases.empty()) gait["phases"] = g.phases;
  if (g.servo_feedforward) gait["servo_feedforward"] = true;  // absent when off: older configs' text unchanged
  if (g.level > 0) gait["level"] = g.level;  // likewise
  json j = {{"torso_body", r.torso_body},
            {"floor_geom", r.floor_geom},
            {"forward_axis", {r.forward_axis.x(), r.forward_axis.y(), r.forward_axis.z()}},
            {"legs", legs},
            {"passive_joints", r.passive_joints},
            {"gait", gait},
            {"overwrite_physics", r.overwrite_physics}};
  if (!r.held_joints.empty()) j["held_joints"] = r.held_joints;  // absent when none: older configs' text unchanged
  if (!r.leg_gain.empty()) j["leg_gain"] = r.leg_gain;
  if (r.controller.replay()) {
    json recordings = json::array();
    for (const auto& rec : r.controller.recordings) {
      recordings.push_back({{"command", {rec.command.x(), rec.command.y(), rec.command.z()}}, {"file", rec.file}});
    }
    j["controller"] = {{"type", r.controller.type}, {"signal", r.controller.signal}, {"recordings", recordings}};
  }
  return j.dump();
}

}  // namespace dgmm::sim
