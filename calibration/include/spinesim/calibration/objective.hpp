// The calibration objective: how far the linearised MSS disc (linear_mss.hpp) is from the FEM
// on the same mesh, and its exact gradient by the adjoint method.
//
// Parameters p_j = ln s_j (log stiffness scales: scale-free steps, s_j > 0 by construction).
// For the training cases c (wrench w_c, FEM vertex displacements u*_c, FEM plate motion q*_c):
//   displacement  J_u = mean_c |R z_c - u*_c|^2 / |u*_c|^2,   K(s) z_c = E_p w_c  (z_c = Z w_c)
//   reaction      J_r = mean_c |S (K6 - K6*) q*_c|^2 / |S K6* q*_c|^2   (the MSS plate moved by
//                 the FEM's motion; S = diag(1,1,1,1/rho,1/rho,1/rho), rho the plate's RMS radius)
//   stiffness     J_k = mean_i ln^2(K6_ii / K6*_ii)   (the 6×6 diagonal, all six directions)
//   regulariser   J_p = mean_j p_j^2                   (ties unidentifiable knobs to Van Gelder)
//   J = J_u + w_r J_r + w_k J_k + w_p J_p.
// Gradient (adjoint of K z = E_p w, one extra solve per case):
//   K lambda_c = dJ_u/dz_c = 2 R^T (R z_c - u*_c) / (N |u*_c|^2),
//   dJ_u/ds_j = -sum_c lambda_c^T K_j z_c,   dK6/ds_j = Phi^T K_j Phi,   dJ/dp_j = s_j dJ/ds_j.
// In general, for any parameter theta of K (a scale, a per-spring multiplier) the data terms
// change by  dJ/dtheta = -sum_c lambda_c^T K_theta z_c + <G6, Phi^T K_theta Phi>,  K_theta = dK/dtheta,
// G6 = d(w_r J_r + w_k J_k)/dK6 (Adjoint; measure()).
// Hessian for Ipopt: J is a weighted sum of squared residuals r (displacement differences,
// scaled reaction differences, log stiffness ratios, p), so the Gauss–Newton matrix
// 2 sum w (dr/dp)^T (dr/dp) is used; dr/dp needs dz_c/ds_j = -K^-1 K_j z_c (one multi-column
// solve). It equals the exact Hessian where the residuals vanish (tested there).
// The errors reported per case are the square roots of the summands (relative, dimensionless):
// the displacement error is the same quantity as `spinesim mss compare`'s, for the linear MSS.
#pragma once

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"

#include <string>
#include <vector>

namespace spinesim::calibration {

/// The FEM's answer for one load case.
struct CaseReference {
  std::string name;
  Vector6d wrench = Vector6d::Zero();        ///< global frame, N and N·mm
  Eigen::VectorXd displacement_mm;           ///< 3#vertices, interleaved, at the mesh vertices
  Vector6d plate_motion = Vector6d::Zero();  ///< (t mm, theta rad)
};

/// FEM reference for a set of load cases on one mesh.
struct FemReference {
  int order = 2;
  Eigen::Vector3d plate_center_mm = Eigen::Vector3d::Zero();
  double plate_rms_radius_mm = 1.0;
  Matrix6d k6 = Matrix6d::Zero();
  std::vector<CaseReference> cases;
};

/// Solves `cases` with `fem` (already factorised) on `mesh` (the mesh fem was built on).
FemReference make_reference(const fem::DiscFem& fem, const mesh::TetMesh& mesh,
                            const std::vector<fem::LoadCase>& cases);

/// RMS distance of the superior-plate vertices from `center_mm` (mm; 1 without plate nodes).
double plate_rms_radius(const mesh::TetMesh& mesh, const Eigen::Vector3d& center_mm);

struct Weights {
  double reaction = 1.0;         ///< w_r
  double stiffness = 1.0;        ///< w_k
  double regularisation = 1e-4;  ///< w_p
};

struct CaseError {
  std::string name;
  double displacement_error = 0;  ///< |R z - u*| / |u*|
  double reaction_error = 0;      ///< |S (K6 - K6*) q*| / |S K6* q*|
};

struct Evaluation {
  double value = 0, displacement = 0, reaction = 0, stiffness = 0, regularisation = 0;
  Eigen::VectorXd gradient;      ///< dJ/dp (empty unless requested)
  Eigen::MatrixXd gauss_newton;  ///< Gauss–Newton approximation of d2J/dp2 (empty unless requested)
  std::vector<CaseError> cases;    ///< every case of the reference, training or not
  Matrix6d k6 = Matrix6d::Zero();  ///< the linearised MSS's plate stiffness
};

/// The data terms' derivative with respect to K in adjoint form (see the header comment):
/// dJ/dtheta = -sum_c lambda_c^T K_theta z_c + <g6, Phi^T K_theta Phi>.
struct Adjoint {
  Eigen::MatrixXd z;       ///< #z × #cases, every reference case's response Z w_c
  Eigen::MatrixXd lambda;  ///< #z × #cases, adjoint solutions (zero columns for untrained cases)
  Eigen::MatrixXd Phi;     ///< #z × 6, condensed modes
  Matrix6d g6 = Matrix6d::Zero();  ///< d(w_r J_r + w_k J_k)/dK6, symmetric
};

class Objective {
 public:
  /// `train`: names of the reference cases J sums over (each must be in `reference`).
  /// Throws std::invalid_argument for an unknown or empty training set, negative weights, or a
  /// reference whose vectors do not fit the model.
  Objective(LinearMss& model, FemReference reference, const std::vector<std::string>& train,
            Weights weights = Weights());

  /// J at log-scales p (and dJ/dp when `with_gradient`, plus the Gauss–Newton Hessian when
  /// `with_hessian`). Throws std::runtime_error when K(s) is not positive definite.
  Evaluation evaluate(const Eigen::VectorXd& log_scales, bool with_gradient,
                      bool with_hessian = false);

  /// The data terms of J (value = J_u + w_r J_r + w_k J_k, no regulariser) and every case's
  /// errors for `state`, the model's last solve; with `adjoint`, also dJ/dK in adjoint form
  /// (one multi-column solve with the same factor).
  Evaluation measure(const LinearState& state, Adjoint* adjoint = nullptr) const;

  const FemReference& reference() const { return ref_; }
  const std::vector<int>& training_cases() const { return train_; }
  const Weights& weights() const { return w_; }
  LinearMss& model() { return model_; }

 private:
  LinearMss& model_;
  FemReference ref_;
  std::vector<int> train_;
  Weights w_;
};

}  // namespace spinesim::calibration
