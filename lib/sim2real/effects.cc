#include "sim2real/effects.h"

#include <algorithm>
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

// A load shift under gravity: (dx, dy) += T (g_x, g_y) with T = [[a, b], [c, -a]] traceless, so
// it holds no isotropic downhill creep (slope_slip's form); (a, b, c) in columns col .. col + 2.
void AddLoadShift(const PoseLayout& layout, const Eigen::Vector3d& g, int col, Eigen::MatrixXd* d) {
  (*d)(layout.dx, col) = g(0);
  (*d)(layout.dy, col) = -g(1);
  (*d)(layout.dx, col + 1) = g(1);
  (*d)(layout.dy, col + 2) = g(0);
}

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
       "an off-centre mass: load shifts between the legs, so the robot drifts (and turns) in a way "
       "that depends on the direction of gravity, and the extra load shortens its strides",
       {{"drift_x", "m per execution"}, {"drift_y", "m per execution (positive: to the left)"},
        {"load_shift_xx", "m per unit gravity: +along x for g_x, -along y for g_y (traceless)"},
        {"drift_x_per_gy", "m per unit gravity along body y"},
        {"drift_y_per_gx", "m per unit gravity along body x"},
        {"yaw_per_gx", "rad per unit gravity along body x"},
        {"yaw_per_gy", "rad per unit gravity along body y"},
        {"load_loss_x", "fraction of the simulated forward displacement lost under the load"},
        {"load_loss_y", "fraction of the simulated lateral displacement lost under the load"},
        {"load_loss_yaw", "fraction of the simulated turn lost under the load"}},
       true, false, false},
      {EffectId::kActuatorAsymmetry, "actuator_asymmetry", "Actuator asymmetry",
       "one side or leg weaker than simulated: the robot turns and drifts as it walks, differently "
       "for each direction of each commanded motion (a weak leg pushes less in one direction than "
       "in the other), more so when the weak side carries more load",
       {{"yaw_per_execution", "rad per execution (positive: to the left)"},
        {"drift_x", "m per execution"},
        {"drift_y", "m per execution (positive: to the left)"},
        {"dy_per_m_forward", "m per metre of simulated forward displacement"},
        {"dy_per_m_backward", "m per metre of simulated backward displacement"},
        {"dy_per_m_left", "m per metre of simulated leftward displacement"},
        {"dy_per_m_right", "m per metre of simulated rightward displacement"},
        {"dy_per_rad_left_turn", "m per rad of simulated left turn"},
        {"dy_per_rad_right_turn", "m per rad of simulated right turn"},
        {"yaw_per_m_forward", "rad per metre of simulated forward displacement"},
        {"yaw_per_m_backward", "rad per metre of simulated backward displacement"},
        {"yaw_per_m_left", "rad per metre of simulated leftward displacement"},
        {"yaw_per_m_right", "rad per metre of simulated rightward displacement"},
        {"yaw_per_rad_left_turn", "rad per rad of simulated left turn"},
        {"yaw_per_rad_right_turn", "rad per rad of simulated right turn"},
        {"yaw_per_gx", "rad per unit gravity along body x"},
        {"yaw_per_gy", "rad per unit gravity along body y"},
        {"load_shift_xx", "m per unit gravity: +along x for g_x, -along y for g_y (traceless)"},
        {"dx_per_gy", "m per unit gravity along body y"},
        {"dy_per_gx", "m per unit gravity along body x"}},
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
    if (e.id == EffectId::kActuatorAsymmetry && !has_terrain) e.parameters.resize(15);
    // Strides and turns are separate motions of the gait (stride length, turn angle), each can
    // lose its own share: one fraction per planar axis when the layout names them.
    if (e.id == EffectId::kStrideLoss && layout.has_planar()) {
      e.parameters = {{"loss_forward", "fraction of the simulated forward displacement"},
                      {"loss_lateral", "fraction of the simulated lateral displacement"}};
      if (layout.dyaw >= 0) e.parameters.push_back({"loss_turn", "fraction of the simulated turn"});
    }
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
      if (effect.num_params() == 1) {
        add_motion(0, -1.0);
      } else {
        d(layout.dx, 0) = -u(layout.dx);
        d(layout.dy, 1) = -u(layout.dy);
        if (effect.num_params() > 2) d(layout.dyaw, 2) = -u(layout.dyaw);
      }
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
      // Coulomb friction: the downhill pull and the friction limit both scale with the total
      // mass, so an added mass creates no isotropic downhill creep (that is slope_slip); the
      // load shift moves the drift anisotropically.
      AddLoadShift(layout, g, 2, &d);
      d(layout.dyaw, 5) = g(0);
      d(layout.dyaw, 6) = g(1);
      d(layout.dx, 7) = -u(layout.dx);
      d(layout.dy, 8) = -u(layout.dy);
      d(layout.dyaw, 9) = -u(layout.dyaw);
      break;
    case EffectId::kActuatorAsymmetry: {
      d(layout.dyaw, 0) = 1.0;
      d(layout.dx, 1) = 1.0;
      d(layout.dy, 2) = 1.0;
      // Per output (dy, dyaw) and per commanded component (forward, lateral, turn as simulated),
      // one coefficient for each direction: (u)+ and (u)-.
      const int out[2] = {layout.dy, layout.dyaw};
      const double in[3] = {u(layout.dx), u(layout.dy), u(layout.dyaw)};
      for (int o = 0; o < 2; ++o) {
        for (int k = 0; k < 3; ++k) {
          d(out[o], 3 + 6 * o + 2 * k) = std::max(in[k], 0.0);
          d(out[o], 4 + 6 * o + 2 * k) = std::max(-in[k], 0.0);
        }
      }
      if (effect.num_params() > 15) {
        // The weak leg's load (and so its sag and lost thrust) changes with the direction of
        // gravity: a turn linear in (g_x, g_y) and a drift through the payload's load-shift map.
        d(layout.dyaw, 15) = g(0);
        d(layout.dyaw, 16) = g(1);
        AddLoadShift(layout, g, 17, &d);
      }
      break;
    }
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
    case EffectId::kExternal:  // designs filled in by their owner (knob_analysis.cc)
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
      if (t.size() > 1) {
        return Format("Executions cover %.0f%% less forward and %.0f%% less sideways ground than "
                      "simulated", 100 * t(0), 100 * t(1)) +
               (t.size() > 2 ? Format(" and turn %.0f%% less", 100 * t(2)) : std::string()) +
               " (less traction or shorter strides; negative: more).";
      }
      return t(0) >= 0 ? Format("Every execution covers %.0f%% less ground and turn than simulated "
                                "(less traction).", 100 * t(0))
                       : Format("Every execution covers %.0f%% more ground and turn than simulated.",
                                -100 * t(0));
    case EffectId::kSlopeTraction:
      return Format("On the observed slope, walking straight downhill covers %.0f%% ", 100 * std::abs(t(0)) * s) +
             (t(0) >= 0 ? "more" : "less") +
             " ground than simulated and walking uphill correspondingly less (more).";
    case EffectId::kPayloadOffset: {
      const double gravity_drift = s * std::max(std::hypot(t(2), t(4)), std::hypot(t(3), t(2)));
      return Format("The centre of mass is off-centre: the robot drifts %.1f mm forward and %.1f mm "
                    "to the left per execution", 1000 * t(0), 1000 * t(1)) +
             Format(", plus up to %.1f mm and %.1f mrad of yaw depending on the direction of gravity "
                    "on the observed slope", 1000 * gravity_drift, 1000 * s * std::hypot(t(5), t(6))) +
             Format("; the load changes forward, lateral and turning motion by %.0f%%, %.0f%% and "
                    "%.0f%%.", -100 * t(7), -100 * t(8), -100 * t(9));
    }
    case EffectId::kActuatorAsymmetry: {
      const double load = e.num_params() > 15 ? s * std::hypot(t(15), t(16)) : 0.0;
      // Largest drift change over the directions of gravity: the operator norm of the 2x2 map.
      const double load_drift =
          e.num_params() > 19 ? s * Eigen::Matrix2d{{t(17), t(18)}, {t(19), -t(17)}}.operatorNorm() : 0.0;
      // The largest direction-dependent term, as a sentence.
      static const char* kDir[6] = {"forward", "backward", "to the left", "to the right",
                                    "turning left", "turning right"};
      static const char* kOut[2] = {"mm to the left", "mrad of turn"};
      int best = 3;
      for (int q = 3; q < 15; ++q) if (std::abs(t(q)) > std::abs(t(best))) best = q;
      const int o = (best - 3) / 6, k = (best - 3) % 6;
      const double typical = k < 4 ? 0.1 : 0.15;  // a typical commanded motion: 10 cm or 0.15 rad
      return Format("One side is weaker than simulated: the robot turns %.1f mrad per execution "
                    "(positive: to the left), up to %.1f mrad more depending on which side is loaded "
                    "on the observed slope, and drifts %.1f mm forward", 1000 * t(0), 1000 * load, 1000 * t(1)) +
             Format(" and %.1f mm to the left per execution (up to %.1f mm more with the load)",
                    1000 * t(2), 1000 * load_drift) +
             Format("; the largest direction-dependent term: %+.1f ", 1000 * t(best) * typical) +
             kOut[o] + " per " + (k < 4 ? "10 cm walked " : "0.15 rad ") + kDir[k] + ".";
    }
    case EffectId::kLatency:
      return Format("The first execution after a change of command loses %.0f%% of its motion "
                    "(backlash or latency).", 100 * t(0));
    case EffectId::kCompliance:
      return (t(0) >= 0 ? Format("The ground gives way: the robot sinks %.1f mm per execution", 1000 * t(0))
                        : Format("The robot ends %.1f mm higher per execution than simulated", -1000 * t(0))) +
             (t(1) >= 0 ? Format(" and its roll and pitch changes are %.0f%% damped.", 100 * t(1))
                        : Format(" and its roll and pitch changes are %.0f%% larger.", -100 * t(1)));
    case EffectId::kBias:
      return "The measured pose change carries a constant offset (tracker or calibration): " +
             Format("|offset| = %.3g in x units.", t.norm());
    case EffectId::kNoise:
      return Format("The real motion is %.2f times as variable as simulated.", std::exp(t(0)));
    case EffectId::kExternal:
      return e.physics;
  }
  return "";
}

}  // namespace dgmm::sim2real
