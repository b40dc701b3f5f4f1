// Time integration of the MSS disc under a Boundary (static equilibrium: solver.hpp).
//
// Equations (positions x, velocities v, lumped masses M, ambient damping K_d (5.11)):
//   M dv/dt = f_int(x) - K_d v + f_ext(x),   dx/dt = v,    f_int = -dE/dx (model.hpp)
// f_ext: probe contact, nodal forces, and for PlateMode::wrench the wrench on the plate DOF.
// Unknowns are the free nodes (no endplate label) plus, for PlateMode::wrench, the six plate
// DOF; endplate nodes in PlateMode::pose follow their poses (Dirichlet).
//
// Integrators (Integrator):
//   explicit_euler    thesis (5.20)-(5.21) exactly: v+ = v + dt a(x, v), x+ = x + dt v (old v).
//                     Stable only for dt < min(K_d / lambda_max(K_ff), 2 m_min / K_d) (ambient
//                     damping K_d per node; the second term is a light overdamped node) — about
//                     5 µs for the real disc, not the thesis's 1 ms. Kept for comparison.
//   symplectic_euler  v+ = v + dt a(x, v), x+ = x + dt v+ ; stable for dt < 2/omega_max undamped,
//                     less where K_d/m is large (predicted_stable_dt_s).
//   implicit_euler    backward Euler as the minimiser of the incremental potential
//                     Phi(x) = |x - x_n - dt v_n|^2_M / (2 dt^2) + K_d |x - x_n|^2/(2 dt) + E(x) - W_ext(x),
//                     by Newton from x_n (endplates at their new poses) with backtracking line
//                     search on Phi; one iteration is exactly Baraff & Witkin's (1998) linearised
//                     step. The matrix M/dt^2 + K_d/dt + K has a fixed pattern: the symbolic
//                     factorisation is done once and reused; MatrixUpdate::frozen also keeps the
//                     numeric factor (rest stiffness; refactorised only when the plate mode or
//                     the wrench-mode centre changes), so a step costs one force evaluation and
//                     one pair of triangular solves. Probe contacts are resolved inside each
//                     linear step by an active-set loop on the linearised gaps, as low-rank
//                     updates of the factor (simulator.cpp): no chatter, no refactorisation.
// Failure: a step that yields non-finite numbers, or moves a node farther from its rest position
// than `divergence_distance_mm` plus the largest displacement of a prescribed endplate node, is
// rejected — the state is left unchanged and StepReport::ok is false with a message. Nothing
// here writes files.
#pragma once

#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>

namespace spinesim::mss {

enum class Integrator { explicit_euler, symplectic_euler, implicit_euler };
enum class MatrixUpdate { every_iteration, frozen };

struct DynamicsOptions {
  Integrator integrator = Integrator::implicit_euler;
  double dt_s = 1e-3;
  int newton_iterations = 1;  ///< implicit: max Newton iterations per step (1 = Baraff–Witkin)
  double newton_relative_tolerance = 1e-6;  ///< implicit: stop early below this residual ratio
  MatrixUpdate matrix_update = MatrixUpdate::every_iteration;
  /// Allowed distance from rest beyond the endplates' own displacement; 0 → the mesh's
  /// bounding-box diagonal.
  double divergence_distance_mm = 0;
};

struct State {
  Eigen::VectorXd x_mm;                    ///< 3#nodes
  Eigen::VectorXd v_mm_s;                  ///< 3#nodes
  Vector6d plate_q = Vector6d::Zero();     ///< plate DOF (t mm, theta rad), PlateMode::wrench
  Vector6d plate_qdot = Vector6d::Zero();  ///< their rates, mm/s, rad/s
  double time_s = 0;
};

struct StepReport {
  bool ok = true;
  int newton_iterations = 0;
  std::string message;  ///< why the step was rejected
};

/// Steps one model under a boundary that may change every step. Holds the factorisation and the
/// model's forces at the last state, so the model must not change (set_scales) while it steps.
class Simulator {
 public:
  /// Throws std::invalid_argument for dt <= 0 or non-finite, newton_iterations < 1.
  Simulator(const MssModel& model, const DynamicsOptions& options);
  ~Simulator();
  Simulator(Simulator&&) noexcept;
  Simulator& operator=(Simulator&&) noexcept;

  /// Rest state, zero velocity, time 0.
  State rest_state() const;
  /// Advances `s` by dt to the boundary `bc_next` (its poses are those at s.time_s + dt; the
  /// endplate velocities follow from the change of pose). Rejects (s unchanged) on divergence.
  StepReport step(State& s, const Boundary& bc_next);
  /// Does now what the first step under `bc`'s plate mode would otherwise do (the reduced system
  /// and, for MatrixUpdate::frozen, its factorisation: ~0.2 s at 20,000 tets), so that the first
  /// loaded step of a real-time loop does not pay for it. False if the matrix is not positive
  /// definite.
  bool prepare(const Boundary& bc);

  /// Largest stable dt of an integrator at rest with both endplates fixed (free nodes; Lanczos
  /// for the extreme eigenvalues). Sufficient conditions from the Jury test of every mode's
  /// Rayleigh quotients (stability.cpp): explicit min(K_d / lambda_max(K_ff), 2 m_min / K_d)
  /// (0 when K_d = 0); symplectic the dt where lambda_max(dt^2 M^-1/2 K M^-1/2 + 2 dt K_d M^-1)
  /// = 4 (2/omega_max undamped); implicit +infinity. Measured limits lie 0-4 % above them.
  double predicted_stable_dt_s(Integrator integrator) const;

  /// A probe's stiffness in the last implicit step's linearisation, -dF/dc (N/mm, symmetric
  /// positive semi-definite): how the disc's force F on the probe (solver.hpp probe_forces)
  /// changes when the probe's centre c moves within a step, the disc answering through the
  /// step's matrix (M/dt^2 + K_d/dt + K, so it includes the step's damping) in series with the
  /// contact penalty. Zero out of contact, before any implicit step with probes, or for an index
  /// outside bc.probes. A multirate renderer's local contact model.
  Eigen::Matrix3d probe_stiffness(int probe) const;

  const DynamicsOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::mss
