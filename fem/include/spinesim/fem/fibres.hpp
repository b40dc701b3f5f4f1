// Linear fibre families in the element stiffness, and the fibre field of a fibre-reinforced
// annulus (mesh::FibreReinforcement).
//
// One family with unit direction a and stiffness k (MPa) adds the strain energy density
// (k/2) (a . eps a)^2, i.e. the stress k (a . eps a) a (x) a and the Voigt elasticity
//   D_f = k m m^T,  m = (a_x^2, a_y^2, a_z^2, a_y a_z, a_x a_z, a_x a_y)
// (Voigt order xx, yy, zz, yz, xz, xy with engineering shear strains, as elasticity.hpp).
// With a . eps a = sum_b (a . g_b)(a . u_b) for shape-function gradients g_b, the element block
// of nodes (a, b) is  K_ab = k (\int (a . g_a)(a . g_b) dV) a a^T.
//
// Fibre field: in every annulus tet two families, a_{1,2} = cos(alpha) e_circ ± sin(alpha) e_axial
// (mesh/annulus_frames.hpp), alpha and E_f by depth, each with k = E_f / 2 (cross-ply laminate).
#pragma once

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

/// Voigt elasticity (MPa) of one fibre family.
Matrix6d fibre_elasticity(const Eigen::Vector3d& direction, double stiffness_mpa);

/// Adds one family's stiffness to an element matrix (12×12 for P1, 30×30 for P2).
void add_fibre_stiffness(const TetVertices& X, const Eigen::Vector3d& direction,
                         double stiffness_mpa, Eigen::Matrix<double, 12, 12>& Ke);
void add_fibre_stiffness(const TetVertices& X, const Eigen::Vector3d& direction,
                         double stiffness_mpa, Eigen::Matrix<double, 30, 30>& Ke);

/// Per-tet fibre families. Rows of tets without fibres have zero stiffness.
struct ElementFibres {
  Eigen::MatrixX3d direction_1;   ///< #T×3 unit, +alpha family
  Eigen::MatrixX3d direction_2;   ///< #T×3 unit, -alpha family
  Eigen::VectorXd stiffness_mpa;  ///< #T, k of each family (E_f / 2); 0 without fibres
  Eigen::VectorXd angle_deg;      ///< #T, alpha; NaN without fibres
  Eigen::VectorXd depth;          ///< #T, depth in the annulus; NaN outside it

  bool empty() const { return stiffness_mpa.size() == 0; }
};

/// The fibre field of `materials` on `mesh` (empty when no region has fibres).
ElementFibres fibre_field(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials);

/// Adds tet t's fibre families (if any) to Ke.
template <class ElementMatrix>
void add_element_fibres(const ElementFibres& fibres, Eigen::Index t, const TetVertices& X,
                        ElementMatrix& Ke) {
  if (fibres.empty() || !(fibres.stiffness_mpa(t) > 0)) return;
  add_fibre_stiffness(X, fibres.direction_1.row(t).transpose(), fibres.stiffness_mpa(t), Ke);
  add_fibre_stiffness(X, fibres.direction_2.row(t).transpose(), fibres.stiffness_mpa(t), Ke);
}

}  // namespace spinesim::fem
