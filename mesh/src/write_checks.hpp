// Private: the checks every mesh writer makes before it touches the disk (VTU, Medit).
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <stdexcept>
#include <string>

namespace spinesim::mesh::detail {

/// Throws std::invalid_argument("<who>...") for an empty mesh, non-finite coordinates,
/// label arrays of the wrong size or vertex indices out of range.
inline void check_mesh_for_writing(const TetMesh& m, const std::string& who) {
  if (m.num_vertices() == 0 || m.num_tets() == 0)
    throw std::invalid_argument(who + "mesh is empty (no vertices or no tetrahedra)");
  if (!m.V.allFinite())
    throw std::invalid_argument(who + "vertex coordinates contain non-finite values");
  if (m.region.size() != m.num_tets())
    throw std::invalid_argument(who + "region labels: expected one per tetrahedron");
  if (m.surface.size() != m.num_vertices())
    throw std::invalid_argument(who + "surface labels: expected one per vertex");
  if (m.T.minCoeff() < 0 || m.T.maxCoeff() >= m.num_vertices())
    throw std::invalid_argument(who + "a tetrahedron has a vertex index out of range");
}

}  // namespace spinesim::mesh::detail
