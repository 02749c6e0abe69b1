#pragma once
// Ground beyond the plane (issue #23): a height field over the slope, described as data (the
// optional `terrain` block of a simulation config) and generated from its seed. Heights are along
// the slope normal, over a square [-half_size, half_size]^2 of the slope frame; the sum of
//   rough ground  h = rms * G / sd(G), G white noise smoothed by a Gaussian of sd = correlation length,
//   stones        caps h = height * sqrt(1 - (r / radius)^2), at seeded random places,
//   steps         terraces h = height * (floor(x / length) mod 2) across the uphill axis.
// Plain data and Eigen: MuJoCo sees it through mujoco_model.cc (an hfield geom that takes over
// the floor's contact parameters).
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace dgmm::sim {

struct RoughGround {
  double rms_height_m = 0;            // 0: none
  double correlation_length_m = 0.1;  // sd of the smoothing kernel
};

struct Stones {
  double height_m = 0;   // 0: none
  double radius_m = 0.05;
  double per_m2 = 4;     // mean number of stones per square metre
};

struct Steps {
  double height_m = 0;   // 0: none
  double length_m = 0.4; // terrace length along the uphill (x) axis
};

struct TerrainDescription {
  std::uint64_t seed = 0;
  double half_size_m = 3.0;    // the ground covers [-half_size, half_size]^2 of the slope frame
  double resolution_m = 0.05;  // grid spacing (MuJoCo makes a contact per penetrated prism: a finer
                               // grid than the feet costs solver time)
  RoughGround rough;
  Stones stones;
  Steps steps;
  // Terrain as the robot senses it at the start of an execution, recorded as extra conditioning
  // dimensions of z after pitch and roll: "foot_relief" (m, sd of the ground's heights under the
  // feet about their least-squares plane: what foot contacts tell with the feet down) and
  // "height_ahead" (m, ground one leg reach ahead minus under the torso: what a depth camera
  // sees). Both exact (no sensor noise).
  std::vector<std::string> sensed;

  // False with a one-line reason (field and expected range); at most kMaxCells grid points.
  bool IsValid(std::string* error) const;
  static constexpr long long kMaxCells = 4'000'000;
  static constexpr double kMaxStones = 1e6;  // expected count
};

// Parses the `terrain` block (JSON text of one object): InputError "<source>: terrain.<field>: <problem>"
// for unknown keys and bad numbers.
TerrainDescription TerrainFromJson(const std::string& json_text, const std::string& source);
// The block as JSON object text (round-trips through TerrainFromJson).
std::string TerrainToJson(const TerrainDescription& terrain);

// Heights on a regular grid: row r at y = -half + r * resolution, column c at x = -half + c * resolution.
class HeightField {
 public:
  // Deterministic per description (seed included).
  static HeightField Generate(const TerrainDescription& terrain);

  // Height (m) at (x, y) of the slope frame, bilinear between grid points; clamped at the edges.
  double At(double x_m, double y_m) const;
  // sd of the heights about their mean (m).
  double RmsHeight() const;
  double min_m() const { return min_; }
  double max_m() const { return max_; }
  int size() const { return n_; }  // grid points per side
  double half_size_m() const { return half_; }
  double resolution_m() const { return resolution_; }
  // Row-major (row = y index), n x n.
  const std::vector<float>& heights() const { return h_; }

 private:
  int n_ = 0;
  double half_ = 0, resolution_ = 0, min_ = 0, max_ = 0;
  std::vector<float> h_;
};

// sd (m) of the points' heights about their least-squares plane z = a + b x + c y (0 for
// fewer than four points).
double FootRelief(const std::vector<Eigen::Vector3d>& feet_m);

// Advice when the ground is far off the robot's scale (empty when it is not): features over half
// the stance height, a grid coarser than 5 foot radii or finer than one, a correlation length
// under two grid points.
std::vector<std::string> TerrainScaleWarnings(const TerrainDescription& terrain, double stance_height_m,
                                              double foot_radius_m);

}  // namespace dgmm::sim
