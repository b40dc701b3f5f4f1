// Element energies of the tetrahedral mass-spring disc (thesis ch. 5), each with its exact
// gradient and Hessian. Every internal force in mss/ is the negative gradient of one of these
// energies, so forces sum to zero force and zero moment and the stiffness is symmetric.
//
// Units: positions mm, stiffness N/mm (springs), N·mm/rad (angle springs: moment per radian
// of opening, energy 1/2 k theta^2 in N·mm with theta in rad), N/mm^5 (volume term); energies
// N·mm, gradients N, Hessians N/mm.
//
// Sign convention: `grad` is dE/dx (the internal force is -grad); `hess` is d2E/dx2.
// Point order in grad/hess: the arguments' order, 3 components each.
//
// HessianMode::exact is the true second derivative (indefinite under compression or for bent
// angles: used by the finite-difference tests, static Newton when it is positive definite).
// HessianMode::projected keeps only the positive semi-definite parts — for edges
// k[uu^T + max(0, 1 - L0/l)(I - uu^T)], for the summed radial spring
// k[∇S∇S^T + max(0, S - S0) H_S] (H_S is PSD: S is a sum of norms of linear maps), for angle
// and volume terms the Gauss–Newton part k ∇θ∇θ^T, k ∇V∇V^T, for the probe k n n^T (n the
// outward normal; the edge formula with L0 = r) — so Cholesky always succeeds (implicit steps,
// Newton fallback).
#pragma once

#include <Eigen/Core>

namespace spinesim::mss {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector9d = Eigen::Matrix<double, 9, 1>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
/// The four vertices of a tetrahedron as columns, mm.
using TetPoints = Eigen::Matrix<double, 3, 4>;

enum class HessianMode { exact, projected };

/// Lengths below this have no direction (coincident spring ends, a vertex at its tet's
/// barycentre, the probe centre on a node): the elements take the zero (sub)gradient there.
inline constexpr double kMinLength_mm = 1e-12;

/// Main (edge) spring, thesis (5.12):  E = 1/2 k (|x1 - x0| - L0)^2.
/// k in N/mm (Van Gelder (5.2): k = sum_tets E_j V_j / L0^2), L0 rest length mm.
double edge_spring(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, double k_n_per_mm,
                   double rest_length_mm, Vector6d* grad = nullptr, Matrix6d* hess = nullptr,
                   HessianMode mode = HessianMode::exact);

/// Radial springs of one tetrahedron, thesis (5.3)-(5.5), as the energy whose gradient's
/// vertex term is (5.4):  S(x) = sum_j |x_j - x_B|, x_B = (1/4) sum_j x_j,
///   E = 1/2 k_s (S - S0)^2,   dE/dx_i = k_s (S - S0) (u_i - (1/4) sum_j u_j),
/// u_j = (x_j - x_B)/|x_j - x_B|. (5.4) keeps only the u_i part; the (1/4) sum u_j part is
/// the barycentre's reaction, without which the forces of one tet do not sum to zero.
double radial_springs(const TetPoints& x, double k_s_n_per_mm, double rest_sum_mm,
                      Vector12d* grad = nullptr, Matrix12d* hess = nullptr,
                      HessianMode mode = HessianMode::exact);

/// Angle between the arms a = x1 - x0 and b = x2 - x0 at the apex x0, radians in [0, pi].
double angle_at(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2);

/// Torsional (angle) spring at apex x0 between arms to x1 and x2, thesis (5.6)-(5.8), (5.13):
///   E = 1/2 k_t (theta - theta0)^2,  theta = angle_at(x0, x1, x2).
/// The gradient acts on the apex as well as on the arm ends: the apex force is minus the sum
/// of the arm-end forces, which (5.13) omits.
double angle_spring(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                    double k_t_nmm_per_rad, double rest_angle_rad, Vector9d* grad = nullptr,
                    Matrix9d* hess = nullptr, HessianMode mode = HessianMode::exact);

/// The thesis's literal torsional force (5.13) for comparison: forces on the two arm ends
/// only, (f1, f2) stacked, N; the apex gets nothing. Equal to -dE/dx1, -dE/dx2 of
/// angle_spring, so its net force is -(apex force) != 0 whenever theta != theta0.
Vector6d thesis_torsion_force(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                              const Eigen::Vector3d& x2, double k_t_nmm_per_rad,
                              double rest_angle_rad);

/// Signed volume of a tetrahedron, mm^3: det[x1-x0, x2-x0, x3-x0] / 6.
double tet_signed_volume(const TetPoints& x);

/// Volume penalty of one tetrahedron (beyond the thesis):  E = 1/2 k_v (V - V0)^2, V signed.
/// With k_v = K_bulk / V0 this is the linear-elastic volumetric energy 1/2 K (dV/V0)^2 V0.
double volume_penalty(const TetPoints& x, double k_v_n_per_mm5, double rest_volume_mm3,
                      Vector12d* grad = nullptr, Matrix12d* hess = nullptr,
                      HessianMode mode = HessianMode::exact);

/// Fibre-direction coefficients of a rest tetrahedron: c_i = ∇N_i · a (1/mm), N_i its linear
/// shape functions and a a unit fibre direction, so that F a = Σ_i c_i x_i for the tet's affine
/// map F, and Σ_i c_i = 0. Throws std::invalid_argument for a degenerate tet.
Eigen::Vector4d fibre_coefficients(const TetPoints& rest, const Eigen::Vector3d& direction);

/// Embedded fibre spring of one tetrahedron (beyond the thesis). A spring lies along the fibre
/// direction a through the tet, its two ends on the tet's faces at fixed barycentric
/// coordinates: it moves with the tet's affine map F, so its stretch is λ = |F a| wherever the
/// line crosses the tet, λ² = I4 = |d|², d = Σ_i c_i x_i (fibre_coefficients). It carries the
/// tet's volume V0 of tension-only exponential fibres — the nonlinear FEM's law
/// (fem/hyperelastic.hpp, Holzapfel, Gasser & Ogden 2000) on the spring's own stretch rather
/// than the isochoric one, since a spring knows only its length:
///   E = V0 k1/(2 k2) [exp(k2 ⟨I4 − 1⟩²) − 1]      (k2 = 0: E = V0 k1/2 ⟨I4 − 1⟩²),
///   dE/dx_i = 2 V0 ψ' c_i d,   d²E/dx_i dx_j = 4 V0 ψ'' c_i c_j d dᵀ + 2 V0 ψ' c_i c_j I,
///   ψ' = k1 (I4 − 1) e,  ψ'' = k1 e (1 + 2 k2 (I4 − 1)²),  e = exp(k2 (I4 − 1)²),
/// all zero for I4 <= 1 (a fibre in compression buckles). Both Hessian parts are positive
/// semi-definite in tension, so there is no projected variant. At small strain ε along a the
/// energy is V0 2 k1 ε²: the linear fibre (fem/fibres.hpp) with k = 4 k1 in tension.
/// k1 MPa (>= 0), k2 dimensionless (>= 0), V0 mm^3; energy N·mm. An exponent past the double
/// range gives an infinite energy (a line search steps back). `rest_i4`: |X c|² at the rest
/// points as computed (1 up to round-off); I4 is divided by it so that the rest state sits
/// exactly at the kink, without stiffness.
double fibre_spring(const TetPoints& x, const Eigen::Vector4d& coefficients, double volume_mm3,
                    double k1_mpa, double k2, Vector12d* grad = nullptr, Matrix12d* hess = nullptr,
                    double rest_i4 = 1.0);

/// The law itself per unit rest volume: ψ(I4) for `excess` = I4 − 1 (or Ī4 − 1), with ψ' and ψ''
/// in `psi1`, `psi2`; all zero for excess <= 0, and a NaN excess returned as the energy.
double fibre_law(double excess, double k1_mpa, double k2, double& psi1, double& psi2);

/// The same law on the tet's isochoric fibre stretch, as the nonlinear FEM takes it:
///   Ī4 = J^(−2/3) I4,  J = det F = det[x1 − x0, x2 − x0, x3 − x0] / `rest_det` (the rest
///   points' same determinant),  E = V0 ψ(Ī4),
///   ∇Ī4 = J^(−2/3) ∇I4 − (2/3) (Ī4 / J) ∇J,
///   ∇²Ī4 = J^(−2/3) ∇²I4 − (2/3) J^(−5/3) (∇I4 ∇Jᵀ + ∇J ∇I4ᵀ) + (10/9) Ī4 J^(−2) ∇J ∇Jᵀ
///          − (2/3) (Ī4 / J) ∇²J,
///   ∇²E = V0 (ψ'' ∇Ī4 ∇Ī4ᵀ + ψ' ∇²Ī4).
/// Not a spring any more — a tet element that sees the volume change, so that a fibre does not
/// stretch merely because its tet swells. The exact Hessian is indefinite (the J terms);
/// HessianMode::projected keeps V0 (ψ'' ∇Ī4 ∇Ī4ᵀ + ψ' J^(−2/3) ∇²I4), positive semi-definite.
/// An inverted tet (J <= 0) has no energy: NaN, as the FEM's.
/// det[x1 − x0, x2 − x0, x3 − x0] as isochoric_fibre computes it: pass this of the rest points
/// as `rest_det`, so that J is exactly 1 at rest (the tension-only kink without stiffness).
double arm_determinant(const TetPoints& x);

double isochoric_fibre(const TetPoints& x, const Eigen::Vector4d& coefficients, double volume_mm3,
                       double k1_mpa, double k2, double rest_det, Vector12d* grad = nullptr,
                       Matrix12d* hess = nullptr, double rest_i4 = 1.0,
                       HessianMode mode = HessianMode::exact);

/// The tension side of a fibre element's Hessian at rest, where the fibre sits at its
/// tension-only kink: V0 k1 g gᵀ, g = ∇Ī4 (isochoric_fibre) or ∇I4 (`isochoric` false:
/// fibre_spring), since ψ'(0) = 0 and ψ''(0⁺) = k1. It is the limit of the exact Hessian as the
/// fibre is stretched from rest; the compression side is zero. `rest` are the rest points and
/// `rest_det`, `rest_i4` their values as the elements take them. A solver that keeps one factor
/// of the rest stiffness needs this side: without it a network whose fibres carry the load is
/// factorised far too soft, and the fixed-matrix step overshoots and diverges.
Matrix12d fibre_rest_tangent(const TetPoints& rest, const Eigen::Vector4d& coefficients,
                             double volume_mm3, double k1_mpa, double rest_det, double rest_i4,
                             bool isochoric);

/// Rigid spherical probe against one node (penalty contact, beyond the thesis): with
/// d = |x - c|, penetration p = max(0, r - d),  E = 1/2 k_p p^2, pushing x out radially.
/// Zero energy, gradient and Hessian when the node is outside the sphere.
double probe_contact(const Eigen::Vector3d& x, const Eigen::Vector3d& center_mm, double radius_mm,
                     double k_p_n_per_mm, Eigen::Vector3d* grad = nullptr,
                     Eigen::Matrix3d* hess = nullptr, HessianMode mode = HessianMode::exact);

}  // namespace spinesim::mss
