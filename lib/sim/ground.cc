#include "sim/ground.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "util/error.h"

namespace dgmm::sim {
namespace {

constexpr const char* kWrapperName = "__dgmm_ground__.xml";
constexpr const char* kGroundName = "dgmm_ground";

// MuJoCo needs a positive elevation range and base thickness (m).
double ElevationRange(const HeightField& f) { return std::max(f.max_m() - f.min_m(), 1e-6); }
double BaseThickness(const HeightField& f) { return std::max(0.05, ElevationRange(f)); }

}  // namespace

std::string GroundWrapperMjcf(const std::string& robot_file, const HeightField& f) {
  char text[1024];
  std::snprintf(text, sizeof text,
                "<mujoco model=\"dgmm ground\">\n"
                "  <include file=\"%s\"/>\n"
                "  <asset><hfield name=\"%s\" nrow=\"%d\" ncol=\"%d\" size=\"%.17g %.17g %.17g %.17g\"/></asset>\n"
                "  <worldbody><geom name=\"%s\" type=\"hfield\" hfield=\"%s\" pos=\"0 0 %.17g\"/></worldbody>\n"
                "</mujoco>\n",
                robot_file.c_str(), kGroundName, f.size(), f.size(), f.half_size_m(), f.half_size_m(),
                ElevationRange(f), BaseThickness(f), kGroundName, kGroundName, f.min_m());
  return text;
}

Ground::Ground(const SimConfig& config) {
  if (config.terrain) field_ = HeightField::Generate(*config.terrain);
}

MjModelPtr Ground::Load(const SimConfig& config) const {
  if (!field_) return LoadRobotModel(config);
  if (config.mjcf_path.empty()) {
    return LoadWithFiles({{"robot.xml", kBuiltinRobotMjcf}, {kWrapperName, GroundWrapperMjcf("robot.xml", *field_)}},
                         kWrapperName, "built-in robot");
  }
  const std::filesystem::path path(config.mjcf_path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw MakeInputError(config.mjcf_path, "MJCF", "file not found");
  const std::string wrapper = GroundWrapperMjcf(path.filename().string(), *field_);
  return LoadWithFiles({{kWrapperName, wrapper}}, (path.parent_path() / kWrapperName).string(), config.mjcf_path);
}

double Ground::MeanUnder(const std::vector<Eigen::Vector3d>& points) const {
  double mean = 0;
  if (!field_) return mean;
  for (const Eigen::Vector3d& p : points) mean += HeightAt(p.x(), p.y()) / points.size();
  return mean;
}

double Ground::HighestUnder(double x_m, double y_m, double heading_rad,
                            const std::vector<Eigen::Vector2d>& offsets) const {
  const Eigen::Rotation2Dd yaw(heading_rad);
  double highest = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& o : offsets) {
    const Eigen::Vector2d at = Eigen::Vector2d(x_m, y_m) + yaw * o;
    highest = std::max(highest, HeightAt(at.x(), at.y()));
  }
  return highest;
}

void Ground::Install(mjModel* m, int floor, const std::string& source) const {
  if (!field_) return;
  const int g = mj_name2id(m, mjOBJ_GEOM, kGroundName);
  const int h = mj_name2id(m, mjOBJ_HFIELD, kGroundName);
  if (g < 0 || h < 0 || floor < 0) throw MakeInputError(source, kGroundName, "the model has no height field ground");
  const int n = m->hfield_nrow[h] * m->hfield_ncol[h];
  if (n != static_cast<int>(field_->heights().size())) throw MakeInputError(source, kGroundName, "height field size mismatch");
  const double lo = field_->min_m(), range = ElevationRange(*field_);
  float* data = m->hfield_data + m->hfield_adr[h];
  for (int i = 0; i < n; ++i) data[i] = static_cast<float>((field_->heights()[i] - lo) / range);
  m->geom_contype[g] = m->geom_contype[floor];
  m->geom_conaffinity[g] = m->geom_conaffinity[floor];
  m->geom_condim[g] = m->geom_condim[floor];
  m->geom_priority[g] = m->geom_priority[floor];
  m->geom_solmix[g] = m->geom_solmix[floor];
  m->geom_margin[g] = m->geom_margin[floor];
  m->geom_gap[g] = m->geom_gap[floor];
  for (int k = 0; k < 3; ++k) m->geom_friction[3 * g + k] = m->geom_friction[3 * floor + k];
  for (int k = 0; k < mjNREF; ++k) m->geom_solref[mjNREF * g + k] = m->geom_solref[mjNREF * floor + k];
  for (int k = 0; k < mjNIMP; ++k) m->geom_solimp[mjNIMP * g + k] = m->geom_solimp[mjNIMP * floor + k];
  for (int k = 0; k < 3; ++k) m->geom_rgba[4 * g + k] = m->geom_rgba[4 * floor + k];
  m->geom_rgba[4 * g + 3] = 1;
  m->geom_contype[floor] = 0;
  m->geom_conaffinity[floor] = 0;
  m->geom_rgba[4 * floor + 3] = 0;
}

}  // namespace dgmm::sim
