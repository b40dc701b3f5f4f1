// LinearMss — the MSS disc linearised at rest, as a function of its stiffness scales: the
// fast, exactly differentiable model the calibration fits to the FEM.
//
// Why at rest: the reference is the *linear* FEM, so the quantity to match is the MSS's
// linear response. The MSS energy is linear in its per-term, per-region scales s_j
// (model.hpp), hence so is its rest Hessian:  K(s) = sum_j s_j K_j,  K_j = term_hessian at
// rest (+ the whole-disc term's rank-one k_g u u^T). Every response below is then exact in s
// and its derivatives follow from dK/ds_j = K_j. The nonlinear MSS at the load cases' loads
// is checked separately (`spinesim mss compare --params`), and agrees to second order in the
// load (tests/mss/test_solver.cpp).
//
// Unknowns z = (u_f, q): the free nodes' displacements (surface label 0 or 3), then the
// superior plate's rigid motion q = (t mm, theta rad) about `plate_center` (the FEM's small-
// rotation map u_i = t + theta x (X_i - c)); inferior-endplate nodes (label 1) are fixed.
// R maps z to all 3#nodes displacements: K(s) = R^T H(s) R.
//   wrench w:   K z = E_p w   (E_p injects into the plate DOF)
//   compliance: Z = K^-1 E_p (#z × 6), C = E_p^T Z, K6 = C^-1, condensed modes Phi = Z K6;
//   so the wrench response is z = Z w, and d K6 / d s_j = Phi^T K_j Phi.
// Per-spring multipliers (per_spring.hpp): at rest an edge spring's Hessian is k_e n nᵀ on its
// two end nodes (n the unit rest direction), so in z it is the rank-one k_e r_e r_eᵀ with
// r_e = Rᵀ b_e, b_e = (−n at node i, +n at node j). With the main springs' region scales s_a, s_n
// and multipliers mu_e:  K(s, mu) = sum_{j not main} s_j K_j + sum_e mu_e k_e(s) r_e r_eᵀ,
// k_e(s) = s_a k_e,a + s_n k_e,n; so dK/d mu_e = k_e(s) r_e r_eᵀ and every derivative is local to
// the edge: aᵀ (dK/d mu_e) b = k_e (n·Δa)(n·Δb), Δa = (R a)_j − (R a)_i (edge_extensions).
// Units: mm, N, N·mm, rad; K6 as fem::DiscFem::stiffness_6x6.
#pragma once

#include "spinesim/mss/model.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <utility>
#include <vector>

namespace spinesim::calibration {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// One calibration knob: the scale of one energy term in one region (0 annulus, 1 nucleus;
/// Term::disc_volume and Term::fibre have region 0 only).
struct Knob {
  mss::Term term = mss::Term::main;
  int region = 0;
  bool operator==(const Knob& o) const { return term == o.term && region == o.region; }
};

/// "main.annulus", "disc_volume", "fibre", ... (the names in tuned.json).
std::string knob_name(const Knob& k);
/// Inverse of knob_name; throws std::invalid_argument for an unknown name.
Knob knob_from_name(const std::string& name);

/// The knobs a model's switched-on terms offer, in Term order (annulus before nucleus).
std::vector<Knob> available_knobs(const mss::MssOptions& options);

/// Linear responses of one factorisation K(s).
struct LinearState {
  Eigen::MatrixXd Z;               ///< #z × 6, K^-1 E_p
  Matrix6d k6 = Matrix6d::Zero();  ///< condensed plate stiffness
  Eigen::MatrixXd Phi;             ///< #z × 6, condensed modes Z K6
};

class LinearMss {
 public:
  /// Precomputes K_j for `knobs` at the rest state of `model` (its current scales are
  /// irrelevant: every K_j is unscaled). Throws std::invalid_argument if a knob's term is off in
  /// the model, the mesh has no superior or no inferior endplate nodes, or the model has fibre
  /// elements (tension only, without stiffness at rest: no linear response to take).
  LinearMss(const mss::MssModel& model, std::vector<Knob> knobs,
            const Eigen::Vector3d& plate_center_mm);
  ~LinearMss();
  LinearMss(LinearMss&&) noexcept;
  LinearMss& operator=(LinearMss&&) noexcept;

  const std::vector<Knob>& knobs() const;
  Eigen::Index num_unknowns() const;  ///< #z = #free DOF + 6
  Eigen::Index num_dofs() const;      ///< 3#nodes

  /// Factorises K(s) (s: one positive scale per knob; the main springs keep the model's own
  /// multipliers) and returns Z, K6, Phi. Throws std::runtime_error when K(s) is not positive
  /// definite.
  LinearState solve(const Eigen::VectorXd& scales);
  /// The same with per-spring multipliers mu (#edge springs, finite > 0, model edge order) in
  /// place of the model's: K(s, mu) above. Needs both main-spring knobs (throws
  /// std::invalid_argument otherwise). K(s, mu)'s values are refilled on the pattern of K(s).
  LinearState solve(const Eigen::VectorXd& scales, const Eigen::VectorXd& edge_multipliers);
  /// K(s)^-1 B with the factor of the last solve() (B: #z × k).
  Eigen::MatrixXd solve_again(const Eigen::MatrixXd& rhs) const;

  /// Full displacement vector R z (3#nodes, interleaved, mm).
  Eigen::VectorXd displacement(const Eigen::VectorXd& z) const;
  /// R^T v for a 3#nodes vector v (the adjoint of displacement()).
  Eigen::VectorXd restrict(const Eigen::VectorXd& v) const;

  Eigen::Index num_edge_springs() const;
  /// k_e(s) = s_a k_e,a + s_n k_e,n for every edge spring (N/mm, #edges): the stiffness at
  /// multiplier 1 under the region scales s.
  Eigen::VectorXd edge_stiffness(const Eigen::VectorXd& scales) const;
  /// r_eᵀ A for every edge spring and column of A (#z × k): n_e·((R a)_j − (R a)_i), the
  /// spring's extension under each column, mm per unit (#edges × k).
  Eigen::MatrixXd edge_extensions(const Eigen::MatrixXd& A) const;

  /// A^T K_j B for every knob j (A: #z × p, B: #z × q): the derivatives of A^T K(s) B.
  std::vector<Eigen::MatrixXd> knob_gram(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) const;
  /// K_j b for knob j (#z), for tests.
  Eigen::VectorXd knob_product(int j, const Eigen::VectorXd& b) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::calibration
