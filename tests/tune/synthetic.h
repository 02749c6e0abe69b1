#pragma once
// Synthetic sample sets for the tune tests: per command c, terrain z ~ N(0, I_2) and pose change
// x = mu_c + B_c z + e, e ~ N(0, noise^2 I_2), with B_c = slope * (a fixed random 2 x 2 matrix)
// (slope = 0: the terrain carries no information about x).
#include <Eigen/Dense>
#include <random>
#include <string>

#include "core/sample_set.h"

namespace dgmm::test {

inline SampleSet MakeTerrainSet(int commands, int per_command, double slope, std::uint64_t seed,
                                double noise = 0.3) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  SampleSet set;
  set.command_dim_names = {"long"};
  set.commands.resize(commands, 1);
  const int n = commands * per_command;
  set.command.resize(n);
  set.x.resize(n, 2);
  set.z.resize(n, 2);
  set.x_names = {"dx", "dy"};
  set.x_units = {"m", "m"};
  set.z_names = {"pitch", "roll"};
  set.z_units = {"rad", "rad"};
  set.source = "synthetic";
  for (int c = 0; c < commands; ++c) {
    set.commands(c, 0) = c;
    set.command_labels.push_back("c" + std::to_string(c));
    const Eigen::Vector2d mu(3.0 * c, -1.0 * c);
    Eigen::Matrix2d B;
    B << 1.0 + 0.2 * c, 0.5, -0.4, 0.8;
    B *= slope;
    for (int j = 0; j < per_command; ++j) {
      // Interleave commands as a recording would: sample i belongs to command i % commands.
      const int i = j * commands + c;
      const Eigen::Vector2d z(normal(rng), normal(rng));
      const Eigen::Vector2d e(normal(rng), normal(rng));
      set.command(i) = c;
      set.z.row(i) = z.transpose();
      set.x.row(i) = (mu + B * z + noise * e).transpose();
    }
  }
  return set;
}

}  // namespace dgmm::test
