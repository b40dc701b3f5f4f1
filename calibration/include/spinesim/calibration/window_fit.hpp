// Identification of a model's parameters from measured windows of positive quantities (a mean
// ± SD, or a published range) with Ipopt: the disc material from in-vitro tests.
//
// Quantity i with window [low_i, high_i] has the residual
//
//   r_i = ln(q_i / sqrt(low_i high_i)) / (½ ln(high_i / low_i)),
//
// the log distance to the window's geometric centre in half-widths: |r_i| <= 1 exactly inside
// the window, and quantities whose sizes differ by decades weigh alike. The unknowns are
// y_j = ln p_j between the logs of each parameter's bounds; the objective is ½ Σ r_i² over the
// quantities in use, its gradient Jᵀr with J = ∂r/∂y from forward differences (the model runs
// once per unknown and point, on `threads` threads), its Hessian the Gauss–Newton JᵀJ.
#pragma once

#include "spinesim/calibration/calibrate.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

namespace spinesim::calibration {

struct WindowTarget {
  std::string name;
  double low = 0, high = 0;  ///< 0 < low < high
};

struct FitParameter {
  std::string name, units;
  double start = 0, lower = 0, upper = 0;  ///< 0 < lower <= start <= upper, lower < upper
};

/// The model: parameters (in FitParameter order) → one positive quantity per target; NaN
/// where the model gives none (a load case that does not converge), which makes Ipopt shorten
/// its step. Must be callable from several threads at once when threads > 1.
using QuantityModel = std::function<Eigen::VectorXd(const Eigen::VectorXd& parameters)>;

struct WindowFitOptions {
  IpoptSettings ipopt;            ///< lower_scale/upper_scale unused: each parameter has its bounds
  double log_step = 1e-3;         ///< forward-difference step in ln p
  int threads = 1;                ///< model evaluations run side by side
  double bound_tolerance = 1e-4;  ///< |ln p - ln bound| below this: the bound is active
};

struct WindowFit {
  bool success = false;
  std::string status;  ///< Ipopt's
  int iterations = 0, model_evaluations = 0;
  double seconds = 0;
  Eigen::VectorXd parameters;              ///< p at the end
  Eigen::VectorXd quantities;              ///< the model there, every target (used or not)
  Eigen::VectorXd residuals;               ///< r_i there, every target
  double objective = 0;                    ///< ½ Σ r_i² over the targets in use
  std::vector<std::string> active_bounds;  ///< e.g. "annulus-E at upper (4.2 MPa)"
};

/// The general form behind fit_to_windows: unknowns y_j = ln p_j between the logs of each
/// parameter's bounds, objective ½ |r(p)|², forward-difference Jacobian (one model run per
/// unknown and point, on `threads` threads), Gauss–Newton Hessian. The model gives the residual
/// vector (of a fixed length) at p; a non-finite entry makes Ipopt shorten its step. Must be
/// callable from several threads at once when threads > 1.
using ResidualModel = std::function<Eigen::VectorXd(const Eigen::VectorXd& parameters)>;

struct LeastSquaresFit {
  bool success = false;
  std::string status;  ///< Ipopt's
  int iterations = 0, model_evaluations = 0;
  double seconds = 0;
  Eigen::VectorXd parameters;              ///< p at the end
  Eigen::VectorXd residuals;               ///< r there
  double objective = 0;                    ///< ½ |r|²
  std::vector<std::string> active_bounds;  ///< e.g. "annulus-E at upper (4.2 MPa)"
};

/// Throws std::invalid_argument (one line) for bad bounds or a start outside them.
LeastSquaresFit fit_least_squares(const ResidualModel& model,
                                  const std::vector<FitParameter>& parameters,
                                  const WindowFitOptions& options = WindowFitOptions(),
                                  const Progress& progress = Progress());

/// r for one quantity (NaN for a non-positive or NaN q).
double window_residual(double quantity, const WindowTarget& target);

/// Throws std::invalid_argument (one line) for bad windows or bounds, a start outside its
/// bounds, `used` of the wrong size or with no target in use.
WindowFit fit_to_windows(const QuantityModel& model, const std::vector<FitParameter>& parameters,
                         const std::vector<WindowTarget>& targets, const std::vector<bool>& used,
                         const WindowFitOptions& options = WindowFitOptions(),
                         const Progress& progress = Progress());

/// Leave-one-out: for each target in use, the fit to the others (started from each parameter's
/// `start`, e.g. the full fit's values); entry i is that fit, or empty (success false, no
/// parameters) for a target not in use or the only one in use. `before` and `after` are called
/// around each fit (progress).
std::vector<WindowFit> leave_one_out(
    const QuantityModel& model, const std::vector<FitParameter>& parameters,
    const std::vector<WindowTarget>& targets, const std::vector<bool>& used,
    const WindowFitOptions& options = WindowFitOptions(),
    const std::function<void(int target)>& before = {},
    const std::function<void(int target, const WindowFit& fit)>& after = {});

}  // namespace spinesim::calibration
