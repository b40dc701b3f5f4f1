// Tet mesh quality report.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <limits>

namespace spinesim::mesh {

struct QualityReport {
  Eigen::Index vertices = 0, tets = 0, annulus_tets = 0, nucleus_tets = 0;
  Eigen::Index inferior_nodes = 0, superior_nodes = 0, wall_nodes = 0;
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  double max_radius_edge_ratio = 0;  ///< circumradius / shortest edge
  double mean_radius_edge_ratio = 0;
  double min_edge_mm = 0, max_edge_mm = 0, mean_edge_mm = 0;
  double volume_mm3 = 0;         ///< sum of tet volumes
  double exact_volume_mm3 = -1;  ///< <0 when unknown
  double volume_error() const {  ///< relative, (mesh - exact)/exact; NaN when unknown
    return exact_volume_mm3 > 0 ? (volume_mm3 - exact_volume_mm3) / exact_volume_mm3
                                : std::numeric_limits<double>::quiet_NaN();
  }
};

/// Counts per region and surface label, interior dihedral angles over all 6 edges of every
/// tet (deg), radius-edge ratio (circumradius / shortest edge of the tet; regular tet:
/// sqrt(6)/4 ≈ 0.612), unique edge lengths (mm) and the mesh volume vs `exact_volume_mm3`.
QualityReport quality_report(const TetMesh& m, double exact_volume_mm3 = -1);

/// The six interior dihedral angles (deg) of tet (a, b, c, d) at edges ab, ac, ad, bc, bd, cd.
std::array<double, 6> dihedral_angles_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, const Eigen::Vector3d& d);

}  // namespace spinesim::mesh
