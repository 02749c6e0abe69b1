#include "sim/contact_extent.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace dgmm::sim {

double ExtentBelow(const mjModel* m, const mjData* d, int g) {
  const mjtNum* s = m->geom_size + 3 * g;
  const Eigen::Matrix3d r = Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(d->geom_xmat + 9 * g);
  const Eigen::Vector3d z = r.row(2).transpose();  // world z in the geom frame
  switch (m->geom_type[g]) {
    case mjGEOM_SPHERE: return s[0];
    case mjGEOM_CAPSULE: return s[0] + s[1] * std::abs(z.z());
    case mjGEOM_CYLINDER: return s[0] * std::sqrt(std::max(0.0, 1 - z.z() * z.z())) + s[1] * std::abs(z.z());
    case mjGEOM_BOX: return s[0] * std::abs(z.x()) + s[1] * std::abs(z.y()) + s[2] * std::abs(z.z());
    case mjGEOM_ELLIPSOID: return Eigen::Vector3d(s[0] * z.x(), s[1] * z.y(), s[2] * z.z()).norm();
    case mjGEOM_MESH: {  // its lowest vertex (vertices in the geom's frame)
      const int mesh = m->geom_dataid[g];
      if (mesh < 0 || m->mesh_vertnum[mesh] == 0) return m->geom_rbound[g];
      double below = -INFINITY;
      for (int v = 0; v < m->mesh_vertnum[mesh]; ++v) {
        const float* p = m->mesh_vert + 3 * (m->mesh_vertadr[mesh] + v);
        below = std::max(below, -(z.x() * p[0] + z.y() * p[1] + z.z() * p[2]));
      }
      return below;
    }
    default: return m->geom_rbound[g];  // height fields, planes: the bounding sphere
  }
}

bool CanTouch(const mjModel* m, int g, int f) {
  if ((m->geom_contype[g] & m->geom_conaffinity[f]) || (m->geom_contype[f] & m->geom_conaffinity[g])) return true;
  for (int p = 0; p < m->npair; ++p) {
    if ((m->pair_geom1[p] == g && m->pair_geom2[p] == f) || (m->pair_geom1[p] == f && m->pair_geom2[p] == g)) {
      return true;
    }
  }
  return false;
}

}  // namespace dgmm::sim
