#include "sim2real/effects.h"

#include <cmath>
#include <cstdio>

namespace dgmm::sim2real {
namespace {

std::string Format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

constexpr double kMinPlanar = 1e-3;  // m: below this the commanded direction is undefined

}  // namespace

std::vector<EffectSpec> EffectLibrary(const PoseLayout& layout, int pose_dim, bool has_terrain,
                                      bool has_sequence) {
  std::vector<EffectSpec> all = {
      {EffectId::kSlopeSlip, "slope_slip", "Slope-induced slip",
       "friction lower than simulated: the robot creeps downhill",
       {{"creep", "m per execution per unit horizontal gravity (x sin(slope) = metres downhill)"}},
       true, false, false},
      {EffectId::kStrideLoss, "stride_loss", "Traction / stride loss",
       "less traction than simulated: every stride covers less ground",
       {{"loss", "fraction of the simulated displacement and turn"}}, false, false, false},
      {EffectId::kSlopeTraction, "slope_traction", "Uphill/downhill traction difference",
       "traction that depends on walking up or down the slope",
       {{"gain", "fraction of displacement gained per unit of downhill alignment"}}, true, false,
       false},
      {EffectId::kPayloadOffset, "payload_offset", "Centre-of-mass / payload offset",
       "an off-centre mass: load shifts between the legs, so the robot drifts and turns in a way "
       "that depends on the direction of gravity",
       {{"drift_x", "m per execution"}, {"drift_y", "m per execution (positive: to the left)"},
        {"drift_x_per_gx", "m per unit gravity along body x"},
        {"drift_x_per_gy", "m per unit gravity along body y"},
        {"drift_y_per_gx", "m per unit gravity along body x"},
        {"drift_y_per_gy", "m per unit gravity along body y"},
        {"yaw_per_gx", "rad per unit gravity along body x"},
        {"yaw_per_gy", "rad per unit gravity along body y"}},
       true, false, false},
      {EffectId::kActuatorAsymmetry, "actuator_asymmetry", "Actuator asymmetry",
       "one side or leg weaker than simulated: the robot turns as it walks (the other way when it "
       "walks backwards), more so when the weak side carries more load",
       {{"yaw_per_execution", "rad per execution (positive: to the left)"},
        {"yaw_per_metre_forward", "rad per metre of forward displacement"},
        {"yaw_per_metre_left", "rad per metre of leftward displacement"},
        {"yaw_per_gx", "rad per unit gravity along body x"},
        {"yaw_per_gy", "rad per unit gravity along body y"}},
       false, false, false},
      {EffectId::kLatency, "latency", "Backlash / latency",
       "motion lost when the command changes (backlash, actuator latency)",
       {{"first_loss", "fraction of the motion lost at the first execution after a change"}},
       false, true, false},
      {EffectId::kCompliance, "compliance", "Terrain compliance",
       "soft ground: the robot sinks and its attitude changes are damped",
       {{"sink", "m per execution (positive: sinks)"},
        {"attitude_damping", "fraction of the simulated roll/pitch change"}},
       false, false, false},
      {EffectId::kBias, "bias", "Constant bias",
       "a constant offset of the measured pose change (tracker or calibration)", {}, false, false,
       false},
      {EffectId::kNoise, "noise", "Noise mis-specification",
       "real motion more variable than simulated (sensor noise, unmodelled disturbances)",
       {{"log_spread_ratio", "log of real / simulated standard deviation"}}, false, false, true},
  };
  for (auto& e : all) {
    if (e.id == EffectId::kActuatorAsymmetry && !has_terrain) e.parameters.resize(3);
    if (e.id == EffectId::kBias) {
      for (int j = 0; j < pose_dim; ++j) e.parameters.push_back({"offset_" + std::to_string(j), "x units"});
    }
  }
  std::vector<EffectSpec> out;
  for (auto& e : all) {
    if (e.needs_terrain && !has_terrain) continue;
    if (e.needs_sequence && !has_sequence) continue;
    const bool planar = layout.has_planar();
    if ((e.id == EffectId::kSlopeSlip || e.id == EffectId::kSlopeTraction ||
         e.id == EffectId::kActuatorAsymmetry) && !planar) continue;
    if ((e.id == EffectId::kPayloadOffset || e.id == EffectId::kActuatorAsymmetry) && layout.dyaw < 0) continue;
    if (e.id == EffectId::kCompliance && layout.dz < 0) continue;
    out.push_back(e);
  }
  return out;
}

Eigen::MatrixXd EffectDesign(const EffectSpec& effect, const PoseLayout& layout,
                             const Eigen::Ref<const Eigen::VectorXd>& u,
                             const Eigen::Ref<const Eigen::Vector3d>& g, bool first) {
  const int dx = static_cast<int>(u.size());
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(dx, effect.num_params());
  // The "motion" the robot was asked to make: planar displacement and turn (all of x when the
  // layout is unknown).
  auto add_motion = [&](int col, double factor) {
    if (layout.has_planar()) {
      d(layout.dx, col) += factor * u(layout.dx);
      d(layout.dy, col) += factor * u(layout.dy);
      if (layout.dyaw >= 0) d(layout.dyaw, col) += factor * u(layout.dyaw);
    } else {
      d.col(col) += factor * u;
    }
  };
  const double planar =
      layout.has_planar() ? std::hypot(u(layout.dx), u(layout.dy)) : 0.0;
  switch (effect.id) {
    case EffectId::kSlopeSlip:
      d(layout.dx, 0) = g(0);
      d(layout.dy, 0) = g(1);
      break;
    case EffectId::kStrideLoss:
      add_motion(0, -1.0);
      break;
    case EffectId::kSlopeTraction: {
      if (planar > kMinPlanar) {
        const double along = (u(layout.dx) * g(0) + u(layout.dy) * g(1)) / planar;
        add_motion(0, along);
      }
      break;
    }
    case EffectId::kPayloadOffset:
      d(layout.dx, 0) = 1.0;
      d(layout.dy, 1) = 1.0;
      d(layout.dx, 2) = g(0);
      d(layout.dx, 3) = g(1);
      d(layout.dy, 4) = g(0);
      d(layout.dy, 5) = g(1);
      d(layout.dyaw, 6) = g(0);
      d(layout.dyaw, 7) = g(1);
      break;
    case EffectId::kActuatorAsymmetry:
      d(layout.dyaw, 0) = 1.0;
      d(layout.dyaw, 1) = u(layout.dx);
      d(layout.dyaw, 2) = u(layout.dy);
      if (effect.num_params() > 3) {
        d(layout.dyaw, 3) = g(0);
        d(layout.dyaw, 4) = g(1);
      }
      break;
    case EffectId::kLatency:
      if (first) add_motion(0, -1.0);
      break;
    case EffectId::kCompliance:
      d(layout.dz, 0) = -1.0;
      if (layout.droll >= 0) d(layout.droll, 1) = -u(layout.droll);
      if (layout.dpitch >= 0) d(layout.dpitch, 1) = -u(layout.dpitch);
      break;
    case EffectId::kBias:
      for (int j = 0; j < dx; ++j) d(j, j) = 1.0;
      break;
    case EffectId::kNoise:
      break;
  }
  return d;
}

std::string DescribeEffect(const EffectSpec& e, const Eigen::VectorXd& t, double s) {
  switch (e.id) {
    case EffectId::kSlopeSlip:
      return t(0) >= 0
                 ? Format("The real robot creeps %.1f mm downhill per execution on the observed slope "
                          "(friction lower than simulated).", 1000 * t(0) * s)
                 : Format("The real robot moves %.1f mm less downhill per execution than simulated "
                          "(friction higher than simulated).", -1000 * t(0) * s);
    case EffectId::kStrideLoss:
      return t(0) >= 0 ? Format("Every execution covers %.0f%% less ground and turn than simulated "
                                "(less traction).", 100 * t(0))
                       : Format("Every execution covers %.0f%% more ground and turn than simulated.",
                                -100 * t(0));
    case EffectId::kSlopeTraction:
      return Format("On the observed slope, walking straight downhill covers %.0f%% ", 100 * std::abs(t(0)) * s) +
             (t(0) >= 0 ? "more" : "less") +
             " ground than simulated and walking uphill correspondingly less (more).";
    case EffectId::kPayloadOffset: {
      const double gravity_drift = s * std::max(std::hypot(t(2), t(4)), std::hypot(t(3), t(5)));
      return Format("The centre of mass is off-centre: the robot drifts %.1f mm forward and %.1f mm "
                    "to the left per execution", 1000 * t(0), 1000 * t(1)) +
             Format(", plus up to %.1f mm and %.1f mrad of yaw depending on the direction of gravity "
                    "on the observed slope.", 1000 * gravity_drift, 1000 * s * std::hypot(t(6), t(7)));
    }
    case EffectId::kActuatorAsymmetry: {
      const double load = e.num_params() > 3 ? s * std::hypot(t(3), t(4)) : 0.0;
      return Format("One side is weaker than simulated: the robot turns %.1f mrad per execution "
                    "(positive: to the left), %.1f mrad per metre walked forward", 1000 * t(0), 1000 * t(1)) +
             Format(" and %.1f mrad per metre walked to the left, up to %.1f mrad more depending on "
                    "which side is loaded on the observed slope.", 1000 * t(2), 1000 * load);
    }
    case EffectId::kLatency:
      return Format("The first execution after a change of command loses %.0f%% of its motion "
                    "(backlash or latency).", 100 * t(0));
    case EffectId::kCompliance:
      return Format("The ground gives way: the robot sinks %.1f mm per execution and its roll and "
                    "pitch changes are %.0f%% damped.", 1000 * t(0), 100 * t(1));
    case EffectId::kBias:
      return "The measured pose change carries a constant offset (tracker or calibration): " +
             Format("|offset| = %.3g in x units.", t.norm());
    case EffectId::kNoise:
      return Format("The real motion is %.2f times as variable as simulated.", std::exp(t(0)));
  }
  return "";
}

}  // namespace dgmm::sim2real
