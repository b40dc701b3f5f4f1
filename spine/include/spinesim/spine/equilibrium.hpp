// Quasi-static equilibrium of the spine under gravity and external loads (spine/README.md):
//  1. recruitment (recruitment.hpp) in the reference posture: the muscles and the
//     recruited joints' springs share the moments of gravity and the external loads;
//  2. Newton with a backtracking line search on the total potential energy Π(θ) over the joint
//     coordinates (finite rotations, kinematics.hpp): joint springs with ROM bumps, tension-only
//     ligaments, the IAP bushing, the recruited muscles as springs T = F·(1 + q·(L − L0)/L0)
//     (short-range stiffness k = q F / L0, Bergmark 1989), dead loads. The gradient is
//     analytic; the Hessian is its central finite difference (symmetrised), shifted when not
//     positive definite so every step descends. Π is C² (stiffness changes ramp in over narrow
//     bands). Sagittal loads on the mirror-symmetric model are solved in the sagittal plane;
//  3. stability: the smallest eigenvalue of the tangent stiffness over all coordinates.
// Returns every vertebra's 6-DOF displacement, joint reactions, ligament and muscle forces.
#pragma once

#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/spine/recruitment.hpp"

#include <Eigen/Core>

#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::spine {

/// External load on a vertebra: force (N) at `point_mm` (reference posture; default the
/// vertebra's F.1 centre) and a couple (N·mm). The force is a dead load (constant direction and
/// magnitude). The couple is made conservative as the potential −M·φ_b (φ_b the vertebra's
/// rotation vector): a dead couple to second order in the rotation.
struct ExternalLoad {
  int vertebra = 0;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_nmm = Eigen::Vector3d::Zero();
  bool has_point = false;
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
};

struct SolveOptions {
  bool recruit = true;  ///< false: muscles off (passive spine)
  RecruitmentOptions recruitment;
  double tolerance = 1e-2;  ///< on max |∂Π/∂θ| in N·mm (generalised moments; 1e-2 N·mm = 10 µN·m)
  double relative_tolerance =
      1e-8;  ///< or max |∂Π/∂θ| ≤ this × its value at θ = 0 (round-off floor)
  int max_iterations = 200;
  double fd_step = 1e-7;  ///< rad, for the finite-difference Hessian
  bool warn_above_600n =
      true;  ///< SpineSolution::warnings names forces beyond 600 N (thesis limit)
  /// Posture (joint coordinates, rad; 3 per joint) at which the muscles are recruited, their
  /// short-range springs rest and Newton starts. Empty: the reference posture θ = 0. The joint
  /// springs, ligaments and bushing keep their reference rest state, so whatever they carry in
  /// this posture is part of what the recruitment balances (a flexed seated lumbar spine).
  Eigen::VectorXd posture;
  /// The model's contact forces (world axes, N, one per SpineModel::contacts) the recruitment
  /// takes as dead loads at the contact points; empty: the contact forces at `posture`.
  std::vector<Eigen::Vector3d> recruitment_contact_forces;
};

/// Force the lower side of a joint exerts on everything above it, and the moment it carries.
struct JointReaction {
  std::string joint;
  Eigen::Vector3d force_world_n;  ///< force of the lower side on everything above, N
  /// Moment about the (moved) joint point of everything acting on the part above: the moment
  /// the joint's spring carries (x > 0: flexion), N·mm.
  Eigen::Vector3d moment_world_nmm;
  /// In the lower vertebra's axes (the thesis's joint frame: F.1 orientations are 0):
  double axial_n = 0;      ///< +y component: compression > 0
  double shear_ap_n = 0;   ///< +z component (the lower body pushes the upper one forward)
  double shear_lat_n = 0;  ///< +x component
  /// In the disc's mid-plane frame (axis from the lower to the upper vertebra centre, as mesh/
  /// places the disc): compression and the shear magnitude in the disc plane.
  double disc_axial_n = 0, disc_shear_n = 0;
  Eigen::Vector3d moment_local_nmm;  ///< x flexion(+)/extension, y torsion, z lateral bending
};

struct SpineSolution {
  bool converged = false;
  int iterations = 0;
  double gradient_norm = 0;  ///< max |∂Π/∂θ| at the end, N·mm
  Eigen::VectorXd theta;     ///< joint coordinates, rad
  std::vector<Pose> poses;
  /// Per vertebra: translation of its F.1 centre (mm) and rotation vector (deg), world axes.
  Eigen::Matrix<double, Eigen::Dynamic, 6> displacement;
  std::vector<JointReaction> joints;
  Eigen::VectorXd ligament_force_n, muscle_force_n;  ///< tensions in the final posture
  Recruitment recruitment;                           ///< the recruited forces F (reference posture)
  Eigen::Matrix<double, 6, 1> bushing_wrench;  ///< IAP force (N) and moment (N·mm) on the ribs
  /// Per SpineModel::contacts: the force the surface exerts on the back (world axes, N) and the
  /// contact point's position (mm) in the final posture.
  std::vector<Eigen::Vector3d> contact_force_n, contact_point_mm;
  /// Smallest eigenvalue of the tangent stiffness ∂²Π/∂θ² at the solution (N·mm/rad; ≤ 0: not
  /// stable) and the joint axis that dominates its mode.
  double min_stiffness_nmm_per_rad = 0;
  std::string softest_mode;
  /// Solved in the sagittal plane (flexion/extension coordinates only): the model is its own
  /// mirror image and every load lies in x = 0, so the equilibrium is symmetric. Its stability is
  /// still judged over all coordinates: not stable means the spine would buckle sideways.
  bool sagittal_solve = false;
  std::vector<std::string> warnings;  ///< forces beyond 600 N, an unstable equilibrium
  double seconds_recruitment = 0, seconds_equilibrium = 0;
};

/// Thrown when Newton does not reach the tolerance: what() gives iterations, the remaining
/// gradient, the worst joint; no partial result is returned.
struct SolveError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Loads no body sees, refused by solve_spine: 100 kN, 10 kN·m, a load point 10 m away.
inline constexpr double kMaxForceN = 1e5, kMaxMomentNmm = 1e7, kMaxPointMm = 1e4;

/// Throws std::invalid_argument for a non-finite load, one beyond any physical load (100 kN, 10 kN·m,
/// a point 10 m away) or an unknown vertebra index, SolveError
/// for a non-converged Newton solve.
SpineSolution solve_spine(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                          const SolveOptions& options = SolveOptions());

/// Rows of a displacement sensitivity: vertebra i's translation (mm) and rotation vector (deg)
/// at rows 6 i … 6 i + 5, as SpineSolution::displacement orders them.
using DisplacementSensitivity = Eigen::Matrix<double, Eigen::Dynamic, 3>;

/// The linear response of `solution` (solved by solve_spine for `loads` with `options`) to the
/// force of loads[load]: d(displacement)/dF, 6·17 × 3, mm/N and deg/N.
///  - Muscles off (or none): the implicit-function derivative dθ/dF = −K⁻¹ ∂g/∂F, K = ∂²Π/∂θ²
///    over every free coordinate (central differences of the analytic gradient, as Newton's),
///    ∂g/∂F exact (Π is linear in a dead load), then displacement(θ) differentiated by central
///    differences along dθ/dF. One Hessian: a few ms.
///  - Recruitment on: the recruited muscles take up most of a load, and how they share it
///    changes with it — the derivative at fixed muscle forces is then several times too large
///    (tests/spine). So the derivative is taken through whole solves: forward differences of
///    solve_spine with a step of `step_n` (N) on each axis, three solves.
/// Throws std::invalid_argument for a load index out of range or a step ≤ 0, SolveError when a
/// differenced solve fails.
/// `fixed_muscles` forces the first method even when the muscles are recruited (a cheap first
/// guess that overestimates the response; tests/spine measure by how much).
enum class SensitivityMethod { automatic, fixed_muscles };
DisplacementSensitivity displacement_sensitivity(
    const SpineModel& m, const std::vector<ExternalLoad>& loads, const SpineSolution& solution,
    int load, const SolveOptions& options = SolveOptions(), double step_n = 5.0,
    SensitivityMethod method = SensitivityMethod::automatic);

/// The spine's state at the posture `theta` for recruited muscle forces `muscle_force_n` (empty:
/// none) under `loads`, without solving: poses, displacements, joint reactions and element
/// forces, as solve_spine reports them (iterations 0, converged false, no recruitment). For a
/// posture that is not an equilibrium the reactions balance whatever loads are given: with the
/// d'Alembert loads of a motion (dynamics.hpp, inertial_loads), they are the motion's.
SpineSolution spine_state(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                          const Eigen::VectorXd& muscle_force_n, const Eigen::VectorXd& theta);

// --- pieces, exposed for tests and the database ---------------------------------------------

/// Total potential energy Π(θ) (N·mm) and its gradient for fixed muscle forces `muscle_force_n`
/// (recruited F; empty = muscles off). Fused joints' coordinates get zero gradient.
double potential(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                 const Eigen::VectorXd& muscle_force_n, const Eigen::VectorXd& theta,
                 Eigen::VectorXd* gradient = nullptr);

/// Moment arms (3 per recruited, non-fused joint × muscles) and load moments, as recruit() takes
/// them, at the posture `theta` (empty: the reference posture) in generalised form: arm(·, i) is
/// −∂L_i/∂θ (the generalised force of a unit tension; at θ = 0 the moment about the joint point)
/// and the loads are ∂Π/∂θ of everything but the muscles (at θ = 0: minus the moment of gravity
/// and the external loads). `contact_forces` (if given, one per contact point) replaces the
/// contact springs by those dead loads.
void recruitment_problem(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                         Eigen::MatrixXd& arm, Eigen::VectorXd& load_moment_nmm,
                         std::vector<int>& joints, const Eigen::VectorXd& theta = Eigen::VectorXd(),
                         const std::vector<Eigen::Vector3d>* contact_forces = nullptr);

}  // namespace spinesim::spine
