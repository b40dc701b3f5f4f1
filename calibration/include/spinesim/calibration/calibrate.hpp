// Fits the MSS stiffness scales to the FEM with Ipopt (interior point, bound constraints
// ln lower <= p_j <= ln upper; the exact gradient and the Gauss–Newton Hessian from
// objective.hpp — limited-memory BFGS needed 170 iterations and ~1,900 evaluations on the
// synthetic test problem, Gauss–Newton 8 iterations and 9 evaluations). Ipopt's C++ TNLP
// interface stays private (src/bounded_nlp.*, shared with the per-spring stage, per_spring.hpp).
#pragma once

#include "spinesim/calibration/objective.hpp"

#include <functional>
#include <string>

namespace spinesim::calibration {

struct IpoptSettings {
  double lower_scale = 1e-3;  ///< bounds on every scale s_j (dimensionless, > 0)
  double upper_scale = 1e3;
  int max_iterations = 300;
  double tolerance = 1e-8;             ///< Ipopt `tol` (scaled NLP error)
  double acceptable_tolerance = 1e-5;  ///< Ipopt `acceptable_tol`
  /// Ipopt `acceptable_iter`: iterations in a row at the acceptable level before it stops there.
  int acceptable_iterations = 15;
  /// Stop once the objective's relative change per iteration has stayed below `stall_change`
  /// this many iterations in a row (0: never); the run then counts as a success with status
  /// "Objective_Stalled". For fits whose gradient comes from finite differences: their noise
  /// keeps Ipopt's own error measure above its tolerances at a point it can no longer improve.
  int stall_iterations = 0;
  double stall_change = 1e-4;
  int print_level = 0;  ///< Ipopt's own output (0 silent ... 12), on stdout
};

/// Called after every Ipopt iteration: iteration number, objective J, the scaled error.
using Progress = std::function<void(int iteration, double objective, double inf_du)>;

struct CalibrationResult {
  bool success = false;  ///< Ipopt solved (or solved to acceptable level)
  std::string status;    ///< Ipopt's return status, e.g. "Solve_Succeeded"
  int iterations = 0;
  int evaluations = 0;  ///< objective (+ gradient) evaluations
  double seconds = 0;
  double evaluation_seconds = 0;                 ///< time inside objective evaluations
  Eigen::VectorXd start_log_scales, log_scales;  ///< p at start and at the end
  Evaluation start, final;  ///< J, its parts and the per-case errors at both ends
};

/// Checks the settings (0 < lower < upper, finite, and validate_stopping's): throws
/// std::invalid_argument naming the problem ("infeasible bounds ...").
void validate(const IpoptSettings& settings);

/// Checks the stopping rules alone (max_iterations >= 1, tolerances > 0, acceptable iterations
/// >= 0), for fits with bounds of their own: throws std::invalid_argument.
void validate_stopping(const IpoptSettings& settings);

/// Runs Ipopt from `start_log_scales` (clamped into the bounds). Never throws for a failed
/// solve: `success` is false and `status` says why; throws std::invalid_argument for bad
/// settings and std::runtime_error when the start point itself cannot be evaluated.
CalibrationResult calibrate(Objective& objective, const Eigen::VectorXd& start_log_scales,
                            const IpoptSettings& settings = IpoptSettings(),
                            const Progress& progress = Progress());

}  // namespace spinesim::calibration
