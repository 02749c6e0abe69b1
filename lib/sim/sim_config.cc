// JSON (nlohmann) loading and saving of SimConfig; strict: unknown keys and wrong types are errors.
#include "sim/sim_config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "sim/json_fields.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

using nlohmann::json;

// A number in its shortest form ("0.2", "0.4").
std::string Shortest(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

bool Check(bool ok, const std::string& message, std::string* error) {
  if (!ok && error) *error = message;
  return ok;
}

bool Finite(double v) { return std::isfinite(v); }

// The built-in robot's payload in absolute bounds; a robot block's only finite here, then checked
// against the robot's own mass and leg reach once it is compiled (legged_robot.cc CheckPayload).
bool CheckPayload(const PayloadConfig& p, bool robot_block, std::string* error) {
  const bool finite = Finite(p.mass_kg) && p.mass_kg >= 0 && p.position_body_m.allFinite();
  if (robot_block) return Check(finite, "payload: expected a finite mass >= 0 kg and a finite position", error);
  return Check(finite && p.mass_kg < 100 && p.position_body_m.cwiseAbs().maxCoeff() <= 1.0,
               "payload: expected mass in [0, 100) kg and position within 1 m of the torso", error);
}

}  // namespace

double MaxLatencyS(const SimConfig& config) {
  const double period = config.robot ? config.robot->gait.period_s : config.gait.period_s;
  return std::isfinite(period) ? std::max(0.2, period / 3) : 0.2;
}

bool SimConfig::IsValid(std::string* error) const {
  const auto& f = friction;
  const auto& m = masses;
  const auto& a = actuators;
  const auto& g = gait;
  const auto& n = noise;
  if (terrain && !terrain->IsValid(error)) return false;
  if (!Check(Finite(slope_deg) && slope_deg > -60 && slope_deg < 60,
             "slope_deg: expected a finite angle in (-60, 60) degrees", error) ||
      !Check(Finite(f.sliding) && f.sliding >= 0 && Finite(f.torsional) && f.torsional >= 0 &&
                 Finite(f.rolling) && f.rolling >= 0,
             "friction: expected finite non-negative coefficients", error) ||
      !Check(Finite(m.torso_kg) && m.torso_kg > 0 && Finite(m.coxa_kg) && m.coxa_kg > 0 &&
                 Finite(m.femur_kg) && m.femur_kg > 0 && Finite(m.tibia_kg) && m.tibia_kg > 0,
             "masses: expected finite positive masses in kg", error) ||
      !CheckPayload(payload, robot.has_value(), error) ||
      !Check(Finite(placement_half_width_m) && placement_half_width_m >= 0,
             "placement_half_width_m: expected a finite width >= 0 m (0: the default)", error) ||
      !Check(Finite(a.kp_nm_per_rad) && a.kp_nm_per_rad > 0 && Finite(a.torque_limit_nm) &&
                 a.torque_limit_nm > 0 && Finite(a.joint_damping_nms_per_rad) &&
                 a.joint_damping_nms_per_rad >= 0,
             "actuators: expected positive kp and torque limit, non-negative damping", error) ||
      !Check(Finite(a.latency_s) && a.latency_s >= 0 && a.latency_s <= MaxLatencyS(*this),
             "actuators.latency_s: expected a value in [0, " + Shortest(MaxLatencyS(*this)) +
                 "] s (a third of the gait's cycle, 0.2 s at the least)",
             error) ||
      !Check(Finite(a.backlash_rad) && a.backlash_rad >= 0 && a.backlash_rad <= 0.2,
             "actuators.backlash_rad: expected a value in [0, 0.2] rad", error))
    return false;
  for (int i = 0; i < kNumLegs; ++i) {
    if (!Check(Finite(a.leg_gain[i]) && a.leg_gain[i] > 0 && a.leg_gain[i] <= 10,
               "actuators.leg_gain: expected 8 values in (0, 10]", error))
      return false;
  }
  if (!Check(Finite(g.period_s) && g.period_s >= 0.1 && g.period_s <= 10 && Finite(g.stride_m) &&
                 g.stride_m >= 0 && g.stride_m <= 0.3 && Finite(g.turn_rad) && g.turn_rad >= 0 &&
                 g.turn_rad <= 1.0 && Finite(g.step_height_m) && g.step_height_m >= 0 &&
                 g.step_height_m <= 0.15 && Finite(g.stance_height_m) &&
                 g.stance_height_m >= 0.05 && g.stance_height_m <= 0.25,
             "gait: period_s in [0.1, 10], stride_m in [0, 0.3], turn_rad in [0, 1], "
             "step_height_m in [0, 0.15], stance_height_m in [0.05, 0.25]",
             error) ||
      !Check(Finite(n.tracker_position_sd_m) && n.tracker_position_sd_m >= 0 &&
                 Finite(n.tracker_yaw_sd_rad) && n.tracker_yaw_sd_rad >= 0 &&
                 Finite(n.tracker_roll_sd_rad) && n.tracker_roll_sd_rad >= 0 &&
                 Finite(n.tracker_pitch_sd_rad) && n.tracker_pitch_sd_rad >= 0 &&
                 Finite(n.imu_pitch_sd_rad) && n.imu_pitch_sd_rad >= 0 &&
                 Finite(n.imu_roll_sd_rad) && n.imu_roll_sd_rad >= 0,
             "noise: expected finite non-negative standard deviations", error) ||
      !Check(Finite(timestep_s) && timestep_s >= 1e-4 && timestep_s <= 0.01,
             "timestep_s: expected a value in [0.0001, 0.01] s", error) ||
      !Check(Finite(settle_duration_s) && settle_duration_s >= 0 && settle_duration_s <= 60,
             "settle_duration_s: expected a value in [0, 60] s", error))
    return false;
  const double period_s = robot ? robot->gait.period_s : g.period_s;  // the gait that runs
  const double cycles = command_duration_s / period_s;
  if (!Check(Finite(command_duration_s) && command_duration_s > 0 && command_duration_s <= 60 &&
                 std::abs(cycles - std::round(cycles)) < 1e-6 && std::round(cycles) >= 1,
             "command_duration_s: expected a whole number (>= 1) of gait periods, at most 60 s",
             error))
    return false;
  return Check(!names.torso_body.empty() && !names.floor_geom.empty() &&
                   !names.actuator_prefix.empty(),
               "names: torso_body, floor_geom and actuator_prefix must not be empty", error);
}

SimConfig SimConfigFromJson(const std::string& json_text, const std::string& source_name) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {  // parse errors, and numbers like 1e400 (out_of_range)
    std::string what = e.what();
    if (what.size() > 200) what = what.substr(0, 200) + "...";
    throw MakeInputError(source_name, "", "not valid JSON: " + what);
  }
  SimConfig c;
  JsonFields r(root, "", source_name);
  r.Number("slope_deg", &c.slope_deg);
  {
    JsonFields f = r.Child("friction");
    f.Number("sliding", &c.friction.sliding);
    f.Number("torsional", &c.friction.torsional);
    f.Number("rolling", &c.friction.rolling);
    f.Done();
  }
  {
    JsonFields m = r.Child("masses");
    m.Number("torso_kg", &c.masses.torso_kg);
    m.Number("coxa_kg", &c.masses.coxa_kg);
    m.Number("femur_kg", &c.masses.femur_kg);
    m.Number("tibia_kg", &c.masses.tibia_kg);
    m.Done();
  }
  {
    JsonFields p = r.Child("payload");
    p.Number("mass_kg", &c.payload.mass_kg);
    p.Numbers<3>("position_body_m", &c.payload.position_body_m);
    p.Done();
  }
  {
    JsonFields a = r.Child("actuators");
    a.Number("kp_nm_per_rad", &c.actuators.kp_nm_per_rad);
    a.Numbers<kNumLegs>("leg_gain", &c.actuators.leg_gain);
    a.Number("joint_damping_nms_per_rad", &c.actuators.joint_damping_nms_per_rad);
    a.Number("torque_limit_nm", &c.actuators.torque_limit_nm);
    a.Number("latency_s", &c.actuators.latency_s);
    a.Number("backlash_rad", &c.actuators.backlash_rad);
    a.Done();
  }
  {
    JsonFields g = r.Child("gait");
    g.Number("period_s", &c.gait.period_s);
    g.Number("stride_m", &c.gait.stride_m);
    g.Number("turn_rad", &c.gait.turn_rad);
    g.Number("step_height_m", &c.gait.step_height_m);
    g.Number("stance_height_m", &c.gait.stance_height_m);
    g.Done();
  }
  {
    JsonFields n = r.Child("noise");
    n.Number("tracker_position_sd_m", &c.noise.tracker_position_sd_m);
    n.Number("tracker_yaw_sd_rad", &c.noise.tracker_yaw_sd_rad);
    n.Number("tracker_roll_sd_rad", &c.noise.tracker_roll_sd_rad);
    n.Number("tracker_pitch_sd_rad", &c.noise.tracker_pitch_sd_rad);
    n.Number("imu_pitch_sd_rad", &c.noise.imu_pitch_sd_rad);
    n.Number("imu_roll_sd_rad", &c.noise.imu_roll_sd_rad);
    n.Done();
  }
  r.Number("timestep_s", &c.timestep_s);
  r.Number("command_duration_s", &c.command_duration_s);
  r.Number("settle_duration_s", &c.settle_duration_s);
  r.Number("placement_half_width_m", &c.placement_half_width_m);
  r.String("mjcf_path", &c.mjcf_path, /*allow_empty=*/true);
  {
    JsonFields n = r.Child("names");
    n.String("torso_body", &c.names.torso_body, /*allow_empty=*/true);
    n.String("floor_geom", &c.names.floor_geom, /*allow_empty=*/true);
    n.String("actuator_prefix", &c.names.actuator_prefix, /*allow_empty=*/true);
    n.Done();
  }
  if (const json* robot = r.Find("robot")) c.robot = RobotDescriptionFromJson(robot->dump(), source_name);
  if (const json* terrain = r.Find("terrain")) c.terrain = TerrainFromJson(terrain->dump(), source_name);
  r.Done();
  std::string error;
  if (!c.IsValid(&error)) throw MakeInputError(source_name, "", error);
  return c;
}

SimConfig LoadSimConfig(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw MakeInputError(path, "", "is a folder, expected a JSON config file");
  }
  if (!std::filesystem::exists(path, ec)) throw MakeInputError(path, "", "file not found");
  std::ifstream in(path);
  if (!in) throw MakeInputError(path, "", "cannot open the config file");
  std::stringstream text;
  text << in.rdbuf();
  SimConfig c = SimConfigFromJson(text.str(), path);
  const auto beside_config = [&](std::string* file) {
    if (!file->empty() && std::filesystem::path(*file).is_relative()) {
      *file = std::filesystem::absolute(std::filesystem::path(path).parent_path() / *file).lexically_normal();
    }
  };
  beside_config(&c.mjcf_path);
  if (c.robot) {
    for (auto& rec : c.robot->controller.recordings) beside_config(&rec.file);
  }
  return c;
}

std::string SimConfigToJson(const SimConfig& c) {
  json j;
  j["slope_deg"] = c.slope_deg;
  j["friction"] = {{"sliding", c.friction.sliding},
                   {"torsional", c.friction.torsional},
                   {"rolling", c.friction.rolling}};
  j["masses"] = {{"torso_kg", c.masses.torso_kg},
                 {"coxa_kg", c.masses.coxa_kg},
                 {"femur_kg", c.masses.femur_kg},
                 {"tibia_kg", c.masses.tibia_kg}};
  const auto& p = c.payload.position_body_m;
  j["payload"] = {{"mass_kg", c.payload.mass_kg},
                  {"position_body_m", {p.x(), p.y(), p.z()}}};
  j["actuators"] = {{"kp_nm_per_rad", c.actuators.kp_nm_per_rad},
                    {"leg_gain", c.actuators.leg_gain},
                    {"joint_damping_nms_per_rad", c.actuators.joint_damping_nms_per_rad},
                    {"torque_limit_nm", c.actuators.torque_limit_nm},
                    {"latency_s", c.actuators.latency_s},
                    {"backlash_rad", c.actuators.backlash_rad}};
  j["gait"] = {{"period_s", c.gait.period_s},
               {"stride_m", c.gait.stride_m},
               {"turn_rad", c.gait.turn_rad},
               {"step_height_m", c.gait.step_height_m},
               {"stance_height_m", c.gait.stance_height_m}};
  j["noise"] = {{"tracker_position_sd_m", c.noise.tracker_position_sd_m},
                {"tracker_yaw_sd_rad", c.noise.tracker_yaw_sd_rad},
                {"tracker_roll_sd_rad", c.noise.tracker_roll_sd_rad},
                {"tracker_pitch_sd_rad", c.noise.tracker_pitch_sd_rad},
                {"imu_pitch_sd_rad", c.noise.imu_pitch_sd_rad},
                {"imu_roll_sd_rad", c.noise.imu_roll_sd_rad}};
  j["timestep_s"] = c.timestep_s;
  j["command_duration_s"] = c.command_duration_s;
  j["settle_duration_s"] = c.settle_duration_s;
  j["mjcf_path"] = c.mjcf_path;
  if (c.placement_half_width_m > 0) j["placement_half_width_m"] = c.placement_half_width_m;  // shipped sets' configs unchanged
  j["names"] = {{"torso_body", c.names.torso_body},
                {"floor_geom", c.names.floor_geom},
                {"actuator_prefix", c.names.actuator_prefix}};
  if (c.robot) j["robot"] = json::parse(RobotDescriptionToJson(*c.robot));
  if (c.terrain) j["terrain"] = json::parse(TerrainToJson(*c.terrain));
  return j.dump(2) + "\n";
}

void SaveSimConfig(const SimConfig& config, const std::string& path) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path());
    out << SimConfigToJson(config);
    if (!out) throw MakeInputError(path, "", "cannot write the config file");
  }
  file.Commit();
}

}  // namespace dgmm::sim
