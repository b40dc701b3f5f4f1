// The total Lagrangian element of the nonlinear disc: a straight P1 or P2 tetrahedron of the
// material of hyperelastic.hpp, its energy, internal force and tangent at nodal displacements u.
//
//   F = I + Σ_a u_a ⊗ ∇N_a          (∇N_a: shape-function gradients in the reference configuration)
//   δE = Σ_a B_a δu_a,  B_a (6×3):  row jj: F_ij ∂_j N_a;  row jk (engineering): F_ij ∂_k N_a + F_ik ∂_j N_a
//   f_a = ∫ B_aᵀ S dV₀                                     (internal force, N)
//   K_ab = ∫ B_aᵀ ℂ B_b + (∇N_a · S ∇N_b) I dV₀             (material + geometric stiffness, N/mm)
//
// (Bonet & Wood, Nonlinear Continuum Mechanics for Finite Element Analysis, ch. 7; Voigt order
// and units as elasticity.hpp.) With VolumetricForm::mean_dilatation, ∫ U(J) dV₀ becomes V₀ U(J̄):
//   f += V₀ U'(J̄) ∂J̄/∂u (through S = p J C⁻¹ at each point, p = U'(J̄)),
//   K += V₀ U''(J̄) d dᵀ, d = ∂J̄/∂u = ∫ J F⁻ᵀ∇N_a dV₀ / V₀.
// Quadrature: one point for P1 (F is constant), the symmetric
// 4-point rule for P2 (as CalculiX's C3D10). DOF order node-major, (x, y, z) per node.
#pragma once

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/hyperelastic.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

/// How the element integrates the volumetric energy U(J):
/// - pointwise: U(J) at each quadrature point — the standard displacement element, as CalculiX's
///   C3D4/C3D10; it locks when K ≫ μ (a nearly incompressible nucleus);
/// - mean_dilatation: V₀ U(J̄) with J̄ = ∫ J dV₀ / V₀, the element's mean dilatation (a constant
///   pressure p = U'(J̄) per element, condensed exactly; Nagtegaal, Parks & Rice 1974; Simo, Taylor
///   & Pister 1985). The isochoric part W̄ stays pointwise. The tangent is symmetric and, for a
///   stable state, positive definite — one Cholesky per Newton step. On P1 J is constant and the
///   two forms coincide; on P2 (P2/P0) it relieves the locking;
/// - nodal_average (P1, a body-level form, hyperelastic_body.hpp): U taken on nodal volumes,
///   Σ_n V_n U(v_n / V_n) with v_n, V_n a quarter of the current and reference volumes of the
///   tets around node n (Bonet & Burton 1998) — one volume constraint per node instead of per
///   tet, which frees the P1 tet from locking while the system stays symmetric positive definite.
enum class VolumetricForm { pointwise, mean_dilatation, nodal_average };

struct HyperelasticElement {
  double energy = 0;        ///< ∫ W dV₀, mJ (N·mm); NaN when a point has no valid state
  Eigen::VectorXd force;    ///< 3·npe internal force, N
  Eigen::MatrixXd tangent;  ///< 3·npe × 3·npe, N/mm (empty unless asked for)
  int inverted_points = 0;  ///< quadrature points with det F <= 0
  double volume_mm3 = 0;    ///< current volume v = ∫ J dV₀
  Eigen::VectorXd volume_gradient;  ///< ∂v/∂u (3·npe), mm²
};

/// `u` is npe×3 (4 or 10 nodes), mm; X the 4 vertices in the reference configuration.
HyperelasticElement hyperelastic_element(int order, const TetVertices& X, const Eigen::MatrixX3d& u,
                                         const FibreHyperelastic& m, bool with_tangent = true,
                                         VolumetricForm form = VolumetricForm::pointwise);

/// The element without a volumetric energy: W̄ at each point and the volumetric stress of the
/// pressure p (MPa) held fixed, i.e. f = ∫ Bᵀ S̄ dV₀ + p ∂v/∂u and the tangent at fixed p. The
/// body builds the nodal-average form from it (p the mean of the element's nodal pressures).
HyperelasticElement hyperelastic_element_at_pressure(int order, const TetVertices& X,
                                                     const Eigen::MatrixX3d& u,
                                                     const FibreHyperelastic& m,
                                                     double pressure_mpa, bool with_tangent = true);

}  // namespace spinesim::fem
