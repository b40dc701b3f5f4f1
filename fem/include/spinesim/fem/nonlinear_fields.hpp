// Per-tet fields of a nonlinear disc state (hyperelastic_body.hpp): the Cauchy stress, von Mises
// stress, pressure, Green–Lagrange strain, principal stretches, fibre stretch and fibre stress per
// family, the volume ratio and the strain energy density — the linear FEM's fields
// (stress_fields.hpp) for finite strain, with units in the names of the arrays that carry them.
//
// Each tet's stress is its volume mean in the deformed configuration, σ_t = (1/v_t) ∫ σ dv, with
// the volumetric part as the body's volumetric form takes it:
//   isochoric σ̄ = J⁻¹ F S̄ Fᵀ at each quadrature point (S̄ of W̄, hyperelastic.hpp), so
//   ∫ σ̄ dv = Σ_q w_q V₀ F S̄ Fᵀ;
//   volumetric  pointwise: U'(J) at each point, ∫ U'(J) J dV₀;  mean_dilatation: U'(J̄) v;
//   nodal_average (P1): the mean over the tet's nodes of U'(J_n), J_n = v_n / V_n the nodal volume
//   ratios (a quarter of the volumes of the tets around the node of the same bulk modulus, as the
//   body keeps them).
// With exactly these, Σ_t v_t σ_t equals Σ_n x_n ⊗ f_n (x current positions, f the internal nodal
// forces the body computes): the discrete virial theorem, the test of these fields, and at
// equilibrium the right-hand side is the sum over the loaded nodes of x ⊗ reaction. The energy
// density is per reference volume, W̄ at the points plus U as the form takes it (nodal average:
// the mean over the tet's nodes of U(J_n)), so Σ_t V₀_t W_t is the body's energy.
// Fibre stretch: λ = |F a| (volume mean over the points); fibre stress: the Cauchy stress along
// the deformed fibre, ā·σ_t ā with ā = F a / |F a| (0 for a tet without that family).
#pragma once

#include "spinesim/fem/hyperelastic_body.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

struct NonlinearElementFields {
  Eigen::MatrixXd cauchy_stress_mpa;          ///< #T×6 (xx, yy, zz, xy, yz, xz), MPa
  Eigen::VectorXd von_mises_mpa;              ///< #T
  Eigen::VectorXd pressure_mpa;               ///< #T, −tr σ / 3 (positive in compression)
  Eigen::MatrixXd green_lagrange_strain;      ///< #T×6, same order, tensor shears (volume mean)
  Eigen::MatrixX3d principal_stretch;         ///< #T×3, descending (of the mean C)
  /// #T×9: their unit directions e1, e2, e3, the eigenvectors of the mean C (material
  /// directions, on the reference tet), each signed so its largest component is positive
  Eigen::MatrixXd principal_stretch_directions;
  Eigen::MatrixX2d fibre_stretch;             ///< #T×2, families 1 and 2 (0: no family)
  Eigen::MatrixX2d fibre_stress_mpa;          ///< #T×2 (0: no family)
  Eigen::VectorXd volume_ratio;               ///< #T, v / V₀
  Eigen::VectorXd strain_energy_density_mpa;  ///< #T, mJ/mm³ of reference volume
};

/// The fields at nodal displacements `u` (3·#nodes, node-major). Throws std::invalid_argument for
/// a wrong size or an inverted element.
NonlinearElementFields nonlinear_element_fields(const HyperelasticBody& body,
                                                const Eigen::VectorXd& u);

}  // namespace spinesim::fem
