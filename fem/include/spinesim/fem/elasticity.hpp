// Small-strain isotropic linear elasticity on straight P1/P2 tetrahedra: element kernels.
//
//   sigma = lambda tr(eps) I + 2 mu eps,  eps = (grad u + grad u^T)/2,
//   K_ab = \int lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I  dV   (3×3 block of nodes a, b;
//   g = shape-function gradient), i.e. the Galerkin form of -div sigma = f
//   (Zienkiewicz & Taylor, The Finite Element Method, vol. 1, ch. 6).
// Units: mm, MPa (N/mm^2) → stiffness N/mm. Voigt order (xx, yy, zz, yz, xz, xy), engineering
// shear strains. Element DOF order: node-major, (u_x, u_y, u_z) of local node 0, then node 1, ...
// P2 shape functions in barycentric L: vertex a: L_a (2 L_a - 1); edge (a,b): 4 L_a L_b, with
// local edge order kP2LocalEdges (fe_space.hpp).
#pragma once

#include "spinesim/mesh/material.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using TetVertices = Eigen::Matrix<double, 4, 3>;  ///< rows: the 4 vertex positions, mm

/// 6×6 Voigt elasticity matrix D (MPa) of an isotropic material: sigma = D eps.
Matrix6d isotropic_elasticity(const mesh::IsotropicMaterial& m);

/// Gradients of the barycentric coordinates (rows, 1/mm) of a straight tet; `volume_mm3` gets
/// the signed volume.
Eigen::Matrix<double, 4, 3> barycentric_gradients(const TetVertices& X, double& volume_mm3);

/// Shape-function values (#npe = 4 or 10) at barycentric point L.
Eigen::VectorXd shape_values(int order, const Eigen::Vector4d& L);

/// Shape-function gradients (#npe×3, 1/mm) at barycentric point L, given grad L.
Eigen::MatrixX3d shape_gradients(int order, const Eigen::Matrix<double, 4, 3>& grad_L,
                                 const Eigen::Vector4d& L);

/// Element stiffness (12×12 for P1, 30×30 for P2), N/mm, of a tet with Lamé constants (MPa).
void element_stiffness_p1(const TetVertices& X, double lambda_mpa, double mu_mpa,
                          Eigen::Matrix<double, 12, 12>& Ke);
void element_stiffness_p2(const TetVertices& X, double lambda_mpa, double mu_mpa,
                          Eigen::Matrix<double, 30, 30>& Ke);
Eigen::MatrixXd element_stiffness(int order, const TetVertices& X,
                                  const mesh::IsotropicMaterial& m);

/// Voigt stress (MPa) at barycentric point L of an element with nodal displacements
/// `ue` (3·npe, mm, node-major).
Vector6d element_stress(int order, const TetVertices& X, const mesh::IsotropicMaterial& m,
                        const Eigen::VectorXd& ue, const Eigen::Vector4d& L);

}  // namespace spinesim::fem
