// The linear disc problem of DiscFem as an Abaqus input deck (.inp) that CalculiX runs as it is.
//
// What the deck holds (keywords as CalculiX 2.20 and Abaqus read them):
//   - *NODE (NSET NALL): the P1 vertices, or the P2 vertices then edge nodes, ids from 1;
//   - *ELEMENT (ELSET EALL): C3D4, or C3D10 (whose mid-edge order, 1-2 2-3 3-1 1-4 2-4 3-4, is
//     ours, fe_space.hpp), ids from 1; ELSET REGION_<r> per mesh region;
//   - materials: per region *ELASTIC (E, nu); a tet with fibres gets its own ELSET and an
//     *ELASTIC, TYPE=ANISO material, D = D_iso + sum_f k_f m_f m_f^T (fibres.hpp) in the global
//     frame — the linear fibre law has no built-in CalculiX counterpart, but its stiffness is
//     exactly an anisotropic elastic tensor, element by element;
//   - NSET INFERIOR (fixed) and SUPERIOR (the plate: vertices labelled 2 and, for P2, edge
//     nodes with both ends labelled 2 — node_surface_labels);
//   - one *STATIC step with the load: a prescribed plate motion as each SUPERIOR node's
//     displacement t + theta x (x - c) (the small-rotation map DiscFem uses), or an applied
//     wrench on a *RIGID BODY of SUPERIOR with REF NODE (force) and ROT NODE (moment) at c;
//   - output: U at every node (*NODE PRINT), S, E and ENER at every integration point
//     (*EL PRINT), and U, S, E to the .frd file for CalculiX GraphiX.
// Units: mm, N, MPa. The mixed formulation has no C3D10 counterpart in CalculiX and is refused.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <ostream>
#include <string>

namespace spinesim::fem {

struct AbaqusDeck {
  int order = 2;                                    ///< 1 (C3D4) or 2 (C3D10)
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero();
  bool prescribed_motion = true;                    ///< else an applied wrench
  Vector6d load = Vector6d::Zero();                 ///< motion (t mm, theta rad) or wrench (N, N·mm)
  std::string title = "spinesim disc";              ///< the *HEADING line
};

/// Writes the deck. Throws std::invalid_argument for an order other than 1 or 2, a mesh
/// without both endplate labels, or a non-finite load.
void write_abaqus_deck(std::ostream& os, const mesh::TetMesh& mesh,
                       const mesh::RegionMaterials& materials, const AbaqusDeck& deck);

}  // namespace spinesim::fem
