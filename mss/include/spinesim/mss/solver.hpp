// Static equilibrium of the MSS disc under a Boundary (time integration: simulator.hpp).
//
// Equations: f_int(x) + f_ext(x) = 0, f_int = -dE/dx (model.hpp); f_ext: probe contact, nodal
// forces, and for PlateMode::wrench the wrench on the plate DOF. Unknowns are the free nodes (no
// endplate label) plus, for PlateMode::wrench, the six plate DOF; endplate nodes in
// PlateMode::pose follow their poses (Dirichlet).
//
// Static solve: Newton with backtracking line search on Pi(x) = E(x) - W_ext(x), with the exact
// Hessian when it factorises and the projected one otherwise.
//
// Nothing here writes files.
#pragma once

#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>

namespace spinesim::mss {

struct StaticOptions {
  /// Converged when |reduced gradient| <= tol * (|dE/dx over all nodes| + |f_ext|), plate
  /// moments over the plate's RMS arm so that all reads in N (solver.cpp).
  double relative_tolerance = 1e-9;
  int max_iterations = 100;
};

struct StaticResult {
  Eigen::VectorXd x_mm;                      ///< 3#nodes equilibrium positions
  Vector6d plate_motion = Vector6d::Zero();  ///< (t mm, theta rad); solved (wrench) or given (pose)
  Vector6d reaction_wrench = Vector6d::Zero();  ///< force N and moment N·mm the disc exerts on
      ///< the superior plate, about the moved plate centre
  bool converged = false;
  int iterations = 0;
  double residual_n = 0;  ///< final |reduced gradient|, N
  double seconds = 0;
  std::string message;  ///< empty when converged, else why not
};

/// Newton equilibrium. `x_start` (3#nodes) may be empty (start from rest, endplates moved).
/// Throws std::invalid_argument for an invalid Boundary.
StaticResult solve_static(const MssModel& model, const Boundary& bc,
                          const StaticOptions& options = StaticOptions(),
                          const Eigen::VectorXd& x_start = Eigen::VectorXd());

/// Reaction wrench of the superior-plate nodes at x: sum of their internal forces -dE/dx_i
/// and the moment about `center_mm` (mm), N and N·mm.
Vector6d plate_reaction(const MssModel& model, const Eigen::VectorXd& x_mm,
                        const Eigen::Vector3d& center_mm);

/// Force the disc exerts on each probe at x (N), same order as bc.probes. A probe with
/// stiffness 0 gets default_probe_stiffness(model), which costs one rest-Hessian evaluation per
/// call: for repeated calls, fill the stiffness in once.
std::vector<Eigen::Vector3d> probe_forces(const MssModel& model, const Boundary& bc,
                                          const Eigen::VectorXd& x_mm);

/// The penalty a probe with stiffness 0 gets (boundary.hpp, Probe), N/mm: 100 trace(K_rest) /
/// (2 #edge springs), K_rest the model's sparse rest Hessian. One Hessian evaluation.
double default_probe_stiffness(const MssModel& model);

}  // namespace spinesim::mss
