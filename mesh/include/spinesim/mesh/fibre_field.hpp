// The fibre field of a fibre-reinforced annulus (FibreReinforcement, material.hpp): in every
// annulus tet two families, a_{1,2} = cos(alpha) e_circ ± sin(alpha) e_axial in the tet's
// lamella frame (annulus_frames.hpp), alpha and E_f by depth, each family with k = E_f / 2
// (cross-ply laminate). A mesh that brings its own fibre directions (TetMesh::fibre_paths, a
// peer model's fibres) sets a_{1,2} instead, tet by tet; alpha is then reported as their mean
// inclination in the lamella frame, and E_f still follows depth. The FEM (fem/fibres.hpp,
// fem/nonlinear_disc.hpp) and the mass-spring disc's fibre springs (mss/model.hpp) read the same
// field.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::mesh {

/// Per-tet fibre families. Rows of tets without fibres have zero stiffness.
struct ElementFibres {
  Eigen::MatrixX3d direction_1;   ///< #T×3 unit, +alpha family
  Eigen::MatrixX3d direction_2;   ///< #T×3 unit, -alpha family
  Eigen::VectorXd stiffness_mpa;  ///< #T, k of each family (E_f / 2); 0 without fibres
  Eigen::VectorXd angle_deg;      ///< #T, alpha (of the mesh's paths when given); NaN without fibres
  Eigen::VectorXd depth;          ///< #T, depth in the annulus; NaN outside it
  Eigen::VectorXd toe_k2;         ///< #T, the region's toe exponent k2; NaN without fibres

  bool empty() const { return stiffness_mpa.size() == 0; }
};

/// The fibre field of `materials` on `mesh` (empty when no region has fibres). Throws
/// std::invalid_argument for fibre paths that validate_fibre_paths refuses.
ElementFibres fibre_field(const TetMesh& mesh, const RegionMaterials& materials);

}  // namespace spinesim::mesh
