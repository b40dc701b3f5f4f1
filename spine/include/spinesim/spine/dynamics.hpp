// Where inertia matters: the spine's natural vibration modes about an equilibrium.
//
// Small motions about an equilibrium θ* obey M θ̈ + K (θ − θ*) = 0, with
//   K = ∂²Π/∂θ² at θ* for the muscle forces the recruitment chose (the muscles' short-range
//       stiffness, the joints, ligaments, IAP and gravity's geometric stiffness: Π's Hessian),
//   M = Σ m_i J_iᵀ J_i, J_i = ∂x_i/∂θ, over the body's point masses: every weight of the model
//       (vertebrae, head and neck, arms) as a mass |W|/g at its load point. The segments'
//       rotational inertia about their own centres is not in the tables and is left out, so the
//       frequencies are upper bounds for the modes that turn single segments.
// The modes solve K φ = ω² M φ over the free coordinates (fused joints excluded). A load that
// changes over a time T_r much longer than the first period T_1 = 1/f_1 is quasi-static: for an
// undamped mode the response to a linear ramp of duration T_r, then held, overshoots its static
// value by |sin x| / x of the ramp's step, x = π T_r / T_1 (the ramp response of a
// single-degree-of-freedom oscillator, e.g. Chopra, Dynamics of Structures, §4.5); its envelope
// min(1, T_1 / (π T_r)) is the bound used here. Damping only lowers it.
#pragma once

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <Eigen/Core>

#include <functional>
#include <vector>

namespace spinesim::spine {

/// Generalised mass matrix at θ (dof_count × dof_count, kg·mm²; zero rows for fused joints).
/// Throws std::invalid_argument for a model without gravity (its masses are its weights).
Eigen::MatrixXd mass_matrix(const SpineModel& m, const Eigen::VectorXd& theta);

/// ∂²Π/∂θ² at θ for fixed recruited muscle forces (N·mm), central differences of the analytic
/// gradient, symmetrised.
Eigen::MatrixXd stiffness_matrix(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                                 const Eigen::VectorXd& muscle_force_n,
                                 const Eigen::VectorXd& theta);

struct NaturalModes {
  Eigen::VectorXd frequency_hz;  ///< ascending
  Eigen::MatrixXd shape;         ///< columns: the modes over all coordinates, φᵀ M φ = 1
  double mass_kg = 0;            ///< the point masses' total
};

/// The `count` lowest modes of K φ = ω² M φ over the coordinates `free` (K, M in N·mm and
/// kg·mm²: ω² = 1000 λ s⁻²). Throws std::invalid_argument when K is not positive definite
/// there (the equilibrium is unstable) or M has no mass.
NaturalModes natural_modes(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M,
                           const std::vector<int>& free, int count);

/// The modes of `solution` (solve_spine of `m` under `loads`).
NaturalModes spine_natural_modes(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                                 const SpineSolution& solution, int count = 6);

// --- the motion -------------------------------------------------------------------------------

/// The loads and the muscle forces at time t (the forces held as recruited: a schedule's
/// quasi-static recruitment, interpolated in time).
using TimeLoads = std::function<void(double t_s, std::vector<ExternalLoad>& loads,
                                     Eigen::VectorXd& muscle_force_n)>;

struct DynamicsOptions {
  double dt_s = 0.005;       ///< time step (> 0, ≤ 0.05 s)
  double damping_ratio = 0;  ///< stiffness-proportional damping, this ratio at the first mode
  int max_iterations = 30;   ///< Newton per step
  double tolerance = 1e-6;   ///< on the residual, relative to the generalised loads' size
};

struct DynamicStep {
  double t_s = 0;
  Eigen::VectorXd theta, velocity, acceleration;  ///< rad, rad/s, rad/s²
  int iterations = 0;
};

/// Integrates M(θ) θ̈ + C θ̇ + ∇Π(θ; F(t), loads(t)) = 0 from θ0 at rest over [t0, t1] with the
/// Newmark average-acceleration rule (trapezoidal: unconditionally stable, no numerical damping),
/// M evaluated at each step's start, C = β K(θ0) with β = 2ζ/ω1. The velocity-squared (Coriolis
/// and centripetal) terms of the equations of motion are left out: they are second order in
/// the slow motions a schedule drives. Fused joints stay at zero. Throws std::invalid_argument for
/// bad options or a scoliotic model (its muscles rest in the curve; not handled here), and
/// SolveError when a step's Newton iteration does not converge.
std::vector<DynamicStep> integrate_spine(const SpineModel& m, const TimeLoads& at,
                                         const Eigen::VectorXd& theta0, double t0, double t1,
                                         const DynamicsOptions& options = DynamicsOptions());

/// The d'Alembert loads −m a of the model's point masses for the joint accelerations θ̈ at θ
/// (a = J θ̈, velocity-squared terms left out as above), one per weight on a vertebra.
std::vector<ExternalLoad> inertial_loads(const SpineModel& m, const Eigen::VectorXd& theta,
                                         const Eigen::VectorXd& acceleration);

/// The bound min(1, T_1 / (π T_r)) on a ramp's dynamic overshoot (a fraction of the ramp's step).
double ramp_overshoot_bound(double first_frequency_hz, double ramp_s);

}  // namespace spinesim::spine
