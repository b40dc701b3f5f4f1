// Private to fem/: Newton's method for a hyperelastic body whose superior endplate rides a rigid
// plate with six unknowns p = (t mm, θ rad), each either driven (a motion) or loaded (a force,
// a moment), the base held (nonlinear_disc.hpp describes the problem).
//
// Plate nodes: u_i = t + R(θ) a_i − a_i, a_i = X_i − c, with the Jacobian
//   J_i = ∂u_i/∂p = [ I | −R(θ) [a_i]× J_r(θ) ]   (J_r the right Jacobian of SO(3)).
// Potential: Π(u_f, p) = E(u) − w·p over the loaded DOF, i.e. a force does the work F·t and a
// moment the work M·θ — exact for a rotation about the moment's axis (the in-vitro tests), a
// second-order approximation of a fixed-direction moment otherwise.
// Newton on (u_f, p_loaded): the free block K_ff by CHOLMOD, the plate DOF by the Schur
// complement S = K_PP − K_fPᵀ K_ff⁻¹ K_fP (6×6 at most); K_pp includes the plate's geometric
// term ∂(Σ J_iᵀ f_i)/∂θ (central differences of a sum over the plate nodes). Load increments,
// a predictor, an Armijo line search on Π and halved increments as in hyperelastic_body.hpp.
#pragma once

#include "spinesim/fem/hyperelastic_body.hpp"

#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

namespace spinesim::fem::detail {

using Vector6 = Eigen::Matrix<double, 6, 1>;

/// ∂(R(θ) a)/∂θ (3×3), R(θ) = rotation_exp(θ) (common/rotation.hpp).
Eigen::Matrix3d rotated_arm_jacobian(const Eigen::Vector3d& theta, const Eigen::Vector3d& arm);

struct PlateProblem {
  std::vector<Eigen::Index> fixed_nodes, plate_nodes;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  std::array<bool, 6> motion_given{};  ///< per plate DOF: driven (true) or loaded (false)
  Vector6 value = Vector6::Zero();     ///< the motion (mm, rad) or the load (N, N·mm)
};

struct PlateNewtonResult {
  HyperelasticSolution body;
  Vector6 plate = Vector6::Zero();               ///< p at the end
  std::vector<std::pair<double, Vector6>> path;  ///< (load fraction, p) per converged increment
};

PlateNewtonResult solve_plate_problem(const HyperelasticBody& body, const PlateProblem& problem,
                                      const NewtonOptions& options);

}  // namespace spinesim::fem::detail
