// Taylor–Hood P2–P1 displacement–pressure formulation, for nearly incompressible regions
// (the nucleus, nu -> 0.5) where the displacement form locks.
//
// Unknowns: P2 displacements u and a P1 mean stress p (MPa, positive in tension; the hydrostatic
// pressure is -p), continuous inside each region and independent across regions (a material
// interface carries a pressure jump, so pressure unknowns are (vertex, region) pairs).
// With the isotropic stress split sigma = 2 mu dev eps + kappa tr(eps) I, kappa = lambda + 2mu/3,
// the weak form is (Hughes, The Finite Element Method, 1987, sec. 4.3; Brezzi & Fortin 1991):
//   a(u, v) + (p, div v)     = f(v)      a(u, v) = \int 2 mu dev eps(u) : dev eps(v) dV + fibres
//   (q, div u) - (p q)/kappa = 0
// In matrix form [[A, B^T], [B, -C]] (u; p) = (f; 0), A = the displacement stiffness with
// (lambda, mu) -> (-2mu/3, mu) plus any fibre families, B_ib = \int L_i dN_b/dx_d dV,
// C = P1 mass / kappa. A is positive definite once rigid motions are fixed and C is positive
// definite, so the matrix is quasi-definite (LDL^T with any ordering; cholmod_solver.hpp).
// Taylor–Hood is inf-sup stable: errors O(h^3) in u and O(h^2) in p (L² norms) uniformly as
// nu -> 0.5 (Boffi, Brezzi & Fortin, Mixed Finite Element Methods, 2013, sec. 8.8).
#pragma once

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"
#include "spinesim/mesh/material.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>

namespace spinesim::fem {

/// P1 pressure unknowns, one per (mesh vertex, region) pair used by a tet.
struct PressureSpace {
  Eigen::MatrixX4i elements;  ///< #T×4 pressure unknown at each tet vertex
  Eigen::VectorXi vertex;     ///< #P mesh vertex of each unknown
  Eigen::VectorXi region;     ///< #P region of each unknown

  Eigen::Index size() const { return vertex.size(); }
};

/// Numbers the pressure unknowns in vertex order (region-major within a vertex).
PressureSpace make_pressure_space(const Eigen::MatrixX4i& T, const Eigen::VectorXi& region);

/// Bulk modulus kappa = lambda + 2 mu / 3 = E / (3 (1 - 2 nu)), MPa.
double bulk_modulus_mpa(const mesh::IsotropicMaterial& m);

/// Element blocks of one straight P2 tet: A (30×30, N/mm), B (4×30, mm^2), C (4×4, mm^3/MPa).
struct MixedElement {
  Eigen::Matrix<double, 30, 30> A;
  Eigen::Matrix<double, 4, 30> B;
  Eigen::Matrix4d C;
};
void element_mixed(const TetVertices& X, double mu_mpa, double kappa_mpa, MixedElement& e);

/// The full symmetric mixed matrix (both triangles) on a P2 space: unknowns 3·node + d (node
/// order), then 3N + pressure index. `fibres` (may be null or empty) adds to A.
Eigen::SparseMatrix<double> assemble_mixed(const FeSpace& p2, const PressureSpace& pressure,
                                           const Eigen::VectorXi& region,
                                           const mesh::RegionMaterials& materials,
                                           const ElementFibres* fibres = nullptr);

/// L² norm of p_h - p_exact over the mesh (pressure values as from the mixed solve, MPa).
double pressure_l2_error(const FeSpace& p2, const PressureSpace& pressure,
                         const Eigen::VectorXd& p_h,
                         const std::function<double(const Eigen::Vector3d&)>& p_exact, int n = 6);

}  // namespace spinesim::fem
