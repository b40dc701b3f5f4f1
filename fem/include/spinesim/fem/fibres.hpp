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
// Fibre field: mesh/fibre_field.hpp (two families per annulus tet, each with k = E_f / 2).
#pragma once

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/mesh/fibre_field.hpp"
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

/// Per-tet fibre families and the field of a material (mesh/fibre_field.hpp).
using mesh::ElementFibres;
using mesh::fibre_field;

/// Adds tet t's fibre families (if any) to Ke.
template <class ElementMatrix>
void add_element_fibres(const ElementFibres& fibres, Eigen::Index t, const TetVertices& X,
                        ElementMatrix& Ke) {
  if (fibres.empty() || !(fibres.stiffness_mpa(t) > 0)) return;
  add_fibre_stiffness(X, fibres.direction_1.row(t).transpose(), fibres.stiffness_mpa(t), Ke);
  add_fibre_stiffness(X, fibres.direction_2.row(t).transpose(), fibres.stiffness_mpa(t), Ke);
}

}  // namespace spinesim::fem
