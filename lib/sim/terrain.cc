#include "sim/terrain.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "core/plane_fit.h"
#include "sim/json_fields.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

using nlohmann::json;

bool Check(bool ok, const std::string& message, std::string* error) {
  if (!ok && error) *error = message;
  return ok;
}

int GridPoints(const TerrainDescription& t) { return 1 + static_cast<int>(std::lround(2 * t.half_size_m / t.resolution_m)); }

// Gaussian smoothing of an n x n grid (row-major), separable, edges clamped.
void Smooth(int n, double sigma_cells, std::vector<double>* grid) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3 * sigma_cells)));
  std::vector<double> kernel(2 * radius + 1);
  double total = 0;
  for (int k = -radius; k <= radius; ++k) total += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma_cells * sigma_cells));
  for (double& w : kernel) w /= total;
  std::vector<double> out(grid->size());
  for (int pass = 0; pass < 2; ++pass) {  // rows, then columns
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) {
        double s = 0;
        for (int k = -radius; k <= radius; ++k) {
          const int i = std::clamp(c + k, 0, n - 1);
          s += kernel[k + radius] * (pass == 0 ? (*grid)[r * n + i] : (*grid)[i * n + r]);
        }
        (pass == 0 ? out[r * n + c] : out[c * n + r]) = s;
      }
    }
    grid->swap(out);
  }
}

// rms * G / sd(G), G smoothed white noise (its own mean removed).
void AddRough(const TerrainDescription& t, int n, std::mt19937_64* rng, std::vector<double>* h) {
  std::normal_distribution<double> normal;
  std::vector<double> g(static_cast<std::size_t>(n) * n);
  for (double& v : g) v = normal(*rng);
  Smooth(n, t.rough.correlation_length_m / t.resolution_m, &g);
  double mean = 0, sq = 0;
  for (double v : g) mean += v;
  mean /= g.size();
  for (double v : g) sq += (v - mean) * (v - mean);
  const double sd = std::sqrt(sq / g.size());
  for (std::size_t i = 0; i < g.size(); ++i) (*h)[i] += sd > 0 ? t.rough.rms_height_m * (g[i] - mean) / sd : 0;
}

// Spherical caps at Poisson(per_m2 * area) uniform places; overlapping stones take the higher.
void AddStones(const TerrainDescription& t, int n, std::mt19937_64* rng, std::vector<double>* h) {
  const double side = 2 * t.half_size_m;
  std::poisson_distribution<long long> count(t.stones.per_m2 * side * side);
  std::uniform_real_distribution<double> where(-t.half_size_m, t.half_size_m);
  std::vector<double> caps(h->size(), 0.0);
  const long long stones = count(*rng);
  const double rad = t.stones.radius_m;
  const int reach = static_cast<int>(std::ceil(rad / t.resolution_m));
  for (long long s = 0; s < stones; ++s) {
    const double sx = where(*rng), sy = where(*rng);
    const int c0 = static_cast<int>(std::lround((sx + t.half_size_m) / t.resolution_m));
    const int r0 = static_cast<int>(std::lround((sy + t.half_size_m) / t.resolution_m));
    for (int r = std::max(0, r0 - reach); r <= std::min(n - 1, r0 + reach); ++r) {
      for (int c = std::max(0, c0 - reach); c <= std::min(n - 1, c0 + reach); ++c) {
        const double dx = -t.half_size_m + c * t.resolution_m - sx, dy = -t.half_size_m + r * t.resolution_m - sy;
        const double q = 1 - (dx * dx + dy * dy) / (rad * rad);
        if (q > 0) caps[r * n + c] = std::max(caps[r * n + c], t.stones.height_m * std::sqrt(q));
      }
    }
  }
  for (std::size_t i = 0; i < h->size(); ++i) (*h)[i] += caps[i];
}

// Alternate terraces across x: up by height every other length.
void AddSteps(const TerrainDescription& t, int n, std::vector<double>* h) {
  for (int c = 0; c < n; ++c) {
    const double x = -t.half_size_m + c * t.resolution_m;
    const long long k = static_cast<long long>(std::floor(x / t.steps.length_m));
    const double step = (k % 2 != 0) ? t.steps.height_m : 0.0;
    for (int r = 0; r < n; ++r) (*h)[r * n + c] += step;
  }
}

std::string Str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

bool TerrainDescription::IsValid(std::string* error) const {
  for (std::size_t i = 0; i < sensed.size(); ++i) {
    const bool known = sensed[i] == "foot_relief" || sensed[i] == "height_ahead";
    if (!Check(known, "terrain.sensed: expected foot_relief or height_ahead, got \"" + sensed[i] + "\"", error) ||
        !Check(std::count(sensed.begin(), sensed.end(), sensed[i]) == 1, "terrain.sensed: " + sensed[i] + " twice", error)) {
      return false;
    }
  }
  const auto finite_pos = [](double v) { return std::isfinite(v) && v > 0; };
  const auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0; };
  if (!Check(finite_pos(half_size_m) && half_size_m <= 1000, "terrain.half_size_m: expected a number in (0, 1000]", error) ||
      !Check(finite_pos(resolution_m) && resolution_m <= half_size_m, "terrain.resolution_m: expected a number in (0, half_size_m]", error)) {
    return false;
  }
  const double n = 1 + 2 * half_size_m / resolution_m;
  if (!Check(n * n <= kMaxCells, "terrain: " + Str(n) + " x " + Str(n) + " grid points, at most " + Str(kMaxCells) +
                                   " (a larger resolution_m or smaller half_size_m)", error)) {
    return false;
  }
  return Check(finite_nonneg(rough.rms_height_m), "terrain.rough.rms_height_m: expected a number >= 0", error) &&
         Check(rough.rms_height_m == 0 || (std::isfinite(rough.correlation_length_m) &&
                                            rough.correlation_length_m >= resolution_m &&
                                            rough.correlation_length_m <= half_size_m),
               "terrain.rough.correlation_length_m: expected a number in [resolution_m, half_size_m]", error) &&
         Check(finite_nonneg(stones.height_m), "terrain.stones.height_m: expected a number >= 0", error) &&
         Check(stones.height_m == 0 ||
                   (std::isfinite(stones.radius_m) && stones.radius_m >= resolution_m && stones.radius_m <= half_size_m),
               "terrain.stones.radius_m: expected a number in [resolution_m, half_size_m]", error) &&
         Check(finite_nonneg(stones.per_m2) && stones.per_m2 <= 1e4, "terrain.stones.per_m2: expected a number in [0, 10000]", error) &&
         Check(stones.height_m == 0 || stones.per_m2 * 4 * half_size_m * half_size_m <= kMaxStones,
               "terrain.stones.per_m2: at most " + Str(kMaxStones) + " stones on the ground (per_m2 x its area)", error) &&
         Check(finite_nonneg(steps.height_m), "terrain.steps.height_m: expected a number >= 0", error) &&
         Check(steps.height_m == 0 || (std::isfinite(steps.length_m) && steps.length_m >= resolution_m),
               "terrain.steps.length_m: expected a number >= resolution_m", error);
}

TerrainDescription TerrainFromJson(const std::string& json_text, const std::string& source) {
  const json root = json::parse(json_text);
  TerrainDescription t;
  JsonFields f(root, "terrain", source);
  double seed = 0;
  f.Number("seed", &seed, 0, 9007199254740992.0);  // 2^53: exact in JSON numbers
  if (seed != std::floor(seed)) f.Fail("terrain.seed", "expected a whole number");
  t.seed = static_cast<std::uint64_t>(seed);
  f.Number("half_size_m", &t.half_size_m, 0, 1000);
  f.Number("resolution_m", &t.resolution_m, 0, 1000);
  const auto child = [&](const char* key, const auto& read) {
    if (const json* v = f.Find(key)) {
      JsonFields c(*v, std::string("terrain.") + key, source);
      read(c);
      c.Done();
    }
  };
  child("rough", [&](JsonFields& c) {
    c.Number("rms_height_m", &t.rough.rms_height_m, 0, 1000);
    c.Number("correlation_length_m", &t.rough.correlation_length_m, 0, 1000);
  });
  child("stones", [&](JsonFields& c) {
    c.Number("height_m", &t.stones.height_m, 0, 1000);
    c.Number("radius_m", &t.stones.radius_m, 0, 1000);
    c.Number("per_m2", &t.stones.per_m2, 0, 1e4);
  });
  f.Strings("sensed", &t.sensed);
  child("steps", [&](JsonFields& c) {
    c.Number("height_m", &t.steps.height_m, 0, 1000);
    c.Number("length_m", &t.steps.length_m, 0, 1000);
  });
  f.Done();
  std::string error;
  if (!t.IsValid(&error)) {
    const auto colon = error.find(": ");
    throw MakeInputError(source, error.substr(0, colon), error.substr(colon + 2));
  }
  return t;
}

std::string TerrainToJson(const TerrainDescription& t) {
  json j;
  j["seed"] = t.seed;
  j["half_size_m"] = t.half_size_m;
  j["resolution_m"] = t.resolution_m;
  j["rough"] = {{"rms_height_m", t.rough.rms_height_m}, {"correlation_length_m", t.rough.correlation_length_m}};
  j["stones"] = {{"height_m", t.stones.height_m}, {"radius_m", t.stones.radius_m}, {"per_m2", t.stones.per_m2}};
  j["steps"] = {{"height_m", t.steps.height_m}, {"length_m", t.steps.length_m}};
  if (!t.sensed.empty()) j["sensed"] = t.sensed;
  return j.dump();
}

HeightField HeightField::Generate(const TerrainDescription& t) {
  std::string error;
  if (!t.IsValid(&error)) throw MakeInputError("terrain", "", error);
  HeightField field;
  const int n = GridPoints(t);
  field.n_ = n;
  field.half_ = t.half_size_m;
  field.resolution_ = t.resolution_m;
  std::vector<double> h(static_cast<std::size_t>(n) * n, 0.0);
  std::mt19937_64 rng(t.seed);
  if (t.rough.rms_height_m > 0) AddRough(t, n, &rng, &h);
  if (t.stones.height_m > 0 && t.stones.per_m2 > 0) AddStones(t, n, &rng, &h);
  if (t.steps.height_m > 0) AddSteps(t, n, &h);
  field.h_.assign(h.begin(), h.end());
  const auto [lo, hi] = std::minmax_element(field.h_.begin(), field.h_.end());
  field.min_ = *lo;
  field.max_ = *hi;
  return field;
}

double HeightField::At(double x_m, double y_m) const {
  const double u = std::clamp((x_m + half_) / resolution_, 0.0, n_ - 1.0);
  const double v = std::clamp((y_m + half_) / resolution_, 0.0, n_ - 1.0);
  const int c = std::min(static_cast<int>(u), n_ - 2);  // n_ >= 3: resolution <= half size
  const int r = std::min(static_cast<int>(v), n_ - 2);
  const double a = u - c, b = v - r;
  const auto H = [&](int rr, int cc) { return static_cast<double>(h_[rr * n_ + cc]); };
  return (1 - b) * ((1 - a) * H(r, c) + a * H(r, c + 1)) + b * ((1 - a) * H(r + 1, c) + a * H(r + 1, c + 1));
}

double HeightField::RmsHeight() const {
  double mean = 0, sq = 0;
  for (float v : h_) mean += v;
  mean /= std::max<std::size_t>(1, h_.size());
  for (float v : h_) sq += (v - mean) * (v - mean);
  return std::sqrt(sq / std::max<std::size_t>(1, h_.size()));
}

double FootRelief(const std::vector<Eigen::Vector3d>& feet) {
  return feet.size() < 4 ? 0.0 : FitPlane(feet).rms_residual;
}

std::vector<std::string> TerrainScaleWarnings(const TerrainDescription& t, double stance_height_m, double foot_radius_m) {
  std::vector<std::string> warnings;
  const auto warn = [&](bool bad, const std::string& what) {
    if (bad) warnings.push_back(what);
  };
  const double tallest = std::max({3 * t.rough.rms_height_m, t.stones.height_m, t.steps.height_m});
  warn(tallest > 0.5 * stance_height_m,
       "terrain: features up to " + Str(tallest) + " m against a stance height of " + Str(stance_height_m) +
           " m; the feet may not clear them (expected under half the stance height)");
  warn(foot_radius_m > 0 && t.resolution_m > 5 * foot_radius_m,
       "terrain.resolution_m: " + Str(t.resolution_m) + " m is over 5 foot radii (" + Str(foot_radius_m) +
           " m); the ground is coarse facets under the feet");
  warn(foot_radius_m > 0 && t.resolution_m < foot_radius_m,
       "terrain.resolution_m: " + Str(t.resolution_m) + " m is under the foot radius (" + Str(foot_radius_m) +
           " m); MuJoCo makes a contact per grid prism under a foot, which slows the simulation (docs/simulation.md)");
  warn(t.rough.rms_height_m > 0 && t.rough.correlation_length_m < 2 * t.resolution_m,
       "terrain.rough.correlation_length_m: under two grid points; the ground is grid noise");
  return warnings;
}

}  // namespace dgmm::sim
