// Private: Ipopt on a bound-constrained problem  min f(p), lower_i <= p_i <= upper_i (by default
// the same bounds for every unknown), shared by the region fit (calibrate.cpp: dense Gauss–Newton
// Hessian) and the per-spring stage (per_spring.cpp: thousands of unknowns, limited-memory
// BFGS). Ipopt's C++ TNLP interface stays inside bounded_nlp.cpp.
#pragma once

#include "spinesim/calibration/calibrate.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>

namespace spinesim::calibration::detail {

/// f, grad f and — for HessianKind::dense only — a symmetric approximation of the Hessian.
struct NlpValues {
  double value = 0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
};
/// Evaluates at p; throws std::runtime_error where the model cannot be evaluated (K not
/// positive definite): Ipopt then shortens the step.
using NlpFunction = std::function<NlpValues(const Eigen::VectorXd& p)>;

enum class HessianKind { dense, limited_memory };

struct NlpRun {
  bool success = false;  ///< Solve_Succeeded or Solved_To_Acceptable_Level
  std::string status;
  int iterations = 0, evaluations = 0;
  double evaluation_seconds = 0;
  Eigen::VectorXd final_point;  ///< empty if Ipopt never reached finalize_solution
};

/// Runs Ipopt from `start` (inside the bounds) with bounds ln settings.lower_scale <= p_i <=
/// ln settings.upper_scale, tolerances, iteration limit and print level from `settings`;
/// `objective_scaling` multiplies f inside Ipopt only (its tolerances are absolute).
NlpRun run_bounded_nlp(const NlpFunction& f, const Eigen::VectorXd& start, HessianKind hessian,
                       const IpoptSettings& settings, const Progress& progress,
                       double objective_scaling = 1.0);

/// The same with a bound pair per unknown (lower(i) < upper(i), in the unknowns' own space);
/// settings.lower_scale and upper_scale are not used.
NlpRun run_bounded_nlp(const NlpFunction& f, const Eigen::VectorXd& start,
                       const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                       HessianKind hessian, const IpoptSettings& settings, const Progress& progress,
                       double objective_scaling = 1.0);

}  // namespace spinesim::calibration::detail
