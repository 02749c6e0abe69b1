#include "tests/sim2real/synthetic.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "sim2real/samples.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// Unit gravity in the body frame at pitch p and roll r (ZYX Euler, x forward, y left, z up).
Eigen::Vector3d BodyGravity(double pitch, double roll) {
  return {std::sin(pitch), -std::sin(roll) * std::cos(pitch), -std::cos(roll) * std::cos(pitch)};
}

// Nominal motion of the analytic robot (m, rad per execution) for command (l, a, t) and unit
// gravity g in the body frame: walking downhill goes a little further.
Eigen::VectorXd Nominal(const Eigen::Vector3d& c, const Eigen::Vector3d& g) {
  Eigen::VectorXd u(6);
  u << 0.20 * c(0) + 0.05 * g(0) * std::abs(c(0)) + 0.01 * g(0),
      0.15 * c(1) + 0.04 * g(1) * std::abs(c(1)) + 0.01 * g(1),
      -0.01 * g(0) * c(0) - 0.01 * g(1) * c(1),
      0.02 * g(1) * std::abs(c(2)) + 0.01 * c(1),
      0.02 * g(0) * std::abs(c(2)) + 0.01 * c(0),
      0.40 * c(2) + 0.03 * c(0) * c(2);
  return u;
}

}  // namespace

SampleSet GenerateSynthetic(const SyntheticWorld& w, const std::string& protocol, std::uint64_t seed) {
  int total;
  if (protocol == "paper") total = 390;
  else if (protocol == "paper-830") total = 830;
  else throw MakeInputError("", "--protocol", "unknown protocol '" + protocol + "' (paper, paper-830)");
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  SampleSet s;
  s.command_dim_names = {"long", "lat", "turn"};
  std::vector<Eigen::Vector3d> table;
  for (double l : {-0.5, 0.0, 0.5}) {
    for (double a : {-0.5, 0.0, 0.5}) {
      for (double t : {-0.5, 0.0, 0.5}) {
        if (l == 0 && a == 0 && t == 0) continue;
        table.emplace_back(l, a, t);
      }
    }
  }
  s.commands.resize(table.size(), 3);
  for (size_t c = 0; c < table.size(); ++c) {
    s.commands.row(c) = table[c].transpose();
    char buf[64];
    std::snprintf(buf, sizeof buf, "%+.1f,%+.1f,%+.1f", table[c](0), table[c](1), table[c](2));
    s.command_labels.push_back(buf);
  }
  s.x_names = {"dx", "dy", "dz", "droll", "dpitch", "dyaw"};
  s.x_units = {"m", "m", "m", "rad", "rad", "rad"};
  s.z_names = {"pitch", "roll"};
  s.z_units = {"rad", "rad"};
  s.source = "synthetic";
  s.metadata["generator"] = "dgmm::sim2real::GenerateSynthetic (analytic stand-in, not MuJoCo)";
  s.metadata["protocol"] = protocol;
  s.metadata["seed"] = std::to_string(seed);
  s.x.resize(total, 6);
  s.z.resize(total, 2);
  s.command.resize(total);
  s.episode.resize(total);
  s.step.resize(total);
  const double alpha = w.slope_deg * std::numbers::pi / 180.0;
  const double headings[3] = {0.0, 90.0, -90.0};
  const Eigen::VectorXd bias = w.bias.size() == 6 ? w.bias : Eigen::VectorXd::Zero(6);
  std::vector<int> order(table.size());
  for (size_t c = 0; c < table.size(); ++c) order[c] = static_cast<int>(c);
  int n = 0, placement = 0;
  while (n < total) {
    std::shuffle(order.begin(), order.end(), rng);  // commands drawn without replacement
    for (int c : order) {
      for (int h = 0; h < 3 && n < total; ++h, ++placement) {
        const double psi = headings[h] * std::numbers::pi / 180.0;
        double pitch = std::asin(std::sin(alpha) * std::sin(psi)) + w.placement_jitter_rad * normal(rng);
        double roll = std::asin(std::sin(alpha) * std::cos(psi) / std::cos(pitch)) +
                      w.placement_jitter_rad * normal(rng);
        const Eigen::Vector3d g = BodyGravity(pitch, roll);
        for (int step = 0; step < 5 && n < total; ++step, ++n) {
          Eigen::VectorXd u = Nominal(table[c], g);
          Eigen::VectorXd x = u + bias;
          const double planar = std::hypot(u(0), u(1));
          Eigen::Vector3d motion(u(0), u(1), u(5));
          auto add_motion = [&](double f) {
            x(0) += f * motion(0);
            x(1) += f * motion(1);
            x(5) += f * motion(2);
          };
          x(0) += w.slip_creep * g(0);
          x(1) += w.slip_creep * g(1);
          add_motion(-w.stride_loss);
          if (planar > 1e-3) add_motion(w.slope_traction * (u(0) * g(0) + u(1) * g(1)) / planar);
          x(1) += w.payload_drift_y;
          x(5) += w.payload_yaw_per_gx * g(0) + w.payload_yaw_per_gy * g(1);
          x(5) += w.asymmetry_yaw_per_execution + w.asymmetry_yaw_per_metre * u(0) +
                  w.asymmetry_yaw_per_gx * g(0);
          if (step == 0) add_motion(-w.latency_first_loss);
          x(2) -= w.sink;
          x(3) -= w.attitude_damping * u(3);
          x(4) -= w.attitude_damping * u(4);
          for (int j = 0; j < 6; ++j) x(j) += w.noise_scale * w.noise_sd(j) * normal(rng);
          s.x.row(n) = x.transpose();
          s.z.row(n) << pitch, roll;
          s.command(n) = c;
          s.episode(n) = placement;
          s.step(n) = step;
        }
      }
    }
  }
  return s;
}

}  // namespace dgmm::sim2real
