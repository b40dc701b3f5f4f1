#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace spinesim::mesh {

double tet_volume(const TetMesh& m, Eigen::Index t) {
  const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                        d = m.V.row(m.T(t, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6.0;
}

double mesh_volume(const TetMesh& m) {
  double v = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) v += tet_volume(m, t);
  return v;
}

void validate(const TetMesh& m) {
  if (m.num_vertices() == 0 || m.num_tets() == 0)
    throw std::invalid_argument("mesh is empty (no vertices or no tetrahedra)");
  if (!m.V.allFinite()) throw std::invalid_argument("mesh has non-finite vertex coordinates");
  // Beyond a kilometre no body is in mm, and volumes of such coordinates overflow or lose every
  // digit (a 1e200 mm point would be reported as a "zero-volume" tetrahedron).
  Eigen::Index row = 0, col = 0;
  if (m.V.cwiseAbs().maxCoeff(&row, &col) > 1e6) {
    std::ostringstream os;
    os << "mesh vertex #" << row << " has a coordinate of " << m.V(row, col)
       << " mm, beyond 1e6 mm (1 km): the mesh is not in mm, or the file is corrupt";
    throw std::invalid_argument(os.str());
  }
  if (m.region.size() != m.num_tets())
    throw std::invalid_argument("mesh region labels: expected one per tetrahedron");
  if (m.surface.size() != m.num_vertices())
    throw std::invalid_argument("mesh surface labels: expected one per vertex");
  if (m.T.minCoeff() < 0 || m.T.maxCoeff() >= m.num_vertices())
    throw std::invalid_argument("mesh has a tetrahedron with a vertex index out of range");
  // Zero volume is judged relative to the mean edge length cubed (scale-free).
  double edge_sum = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    edge_sum += (m.V.row(m.T(t, 1)) - m.V.row(m.T(t, 0))).norm();
  const double h = edge_sum / double(m.num_tets());
  const double tiny = 1e-12 * h * h * h;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const double v = tet_volume(m, t);
    if (!(v > tiny)) {
      std::ostringstream os;
      os << "mesh has an " << (v < -tiny ? "inverted" : "zero-volume") << " tetrahedron (#" << t
         << ", signed volume " << v << " mm^3)";
      throw std::invalid_argument(os.str());
    }
  }
}

void require_endplate_labels(const TetMesh& m) {
  const bool has_inferior = (m.surface.array() == int(Surface::inferior_endplate)).any();
  const bool has_superior = (m.surface.array() == int(Surface::superior_endplate)).any();
  if (!has_inferior || !has_superior)
    throw std::invalid_argument(
        "mesh has no endplate labels (point data 'surface' needs nodes labelled 1 = inferior "
        "and 2 = superior endplate)");
}

}  // namespace spinesim::mesh
