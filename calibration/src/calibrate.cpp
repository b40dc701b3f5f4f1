#include "spinesim/calibration/calibrate.hpp"

#include "spinesim/common/timer.hpp"

#include "bounded_nlp.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::calibration {

void validate_stopping(const IpoptSettings& s) {
  if (s.max_iterations < 1) throw std::invalid_argument("calibration: max iterations must be >= 1");
  if (!(s.tolerance > 0) || !(s.acceptable_tolerance > 0) || !(s.stall_change > 0))
    throw std::invalid_argument("calibration: Ipopt tolerances must be > 0");
  if (s.acceptable_iterations < 0 || s.stall_iterations < 0)
    throw std::invalid_argument("calibration: Ipopt acceptable and stall iterations must be >= 0");
}

void validate(const IpoptSettings& s) {
  validate_stopping(s);
  if (!std::isfinite(s.lower_scale) || !std::isfinite(s.upper_scale) || s.lower_scale <= 0)
    throw std::invalid_argument("calibration: scale bounds must be finite and > 0");
  if (!(s.lower_scale < s.upper_scale))
    throw std::invalid_argument("calibration: infeasible bounds, lower scale " +
                                std::to_string(s.lower_scale) + " is not below upper scale " +
                                std::to_string(s.upper_scale));
}

CalibrationResult calibrate(Objective& objective, const Eigen::VectorXd& start_log_scales,
                            const IpoptSettings& settings, const Progress& progress) {
  validate(settings);
  const Timer t0;
  CalibrationResult out;
  out.start_log_scales = start_log_scales.cwiseMax(std::log(settings.lower_scale))
                             .cwiseMin(std::log(settings.upper_scale));
  out.start = objective.evaluate(out.start_log_scales, false);  // throws if the start is unusable

  const detail::NlpFunction f = [&objective](const Eigen::VectorXd& p) {
    Evaluation ev = objective.evaluate(p, true, true);
    return detail::NlpValues{ev.value, std::move(ev.gradient), std::move(ev.gauss_newton)};
  };
  const detail::NlpRun run = detail::run_bounded_nlp(
      f, out.start_log_scales, detail::HessianKind::dense, settings, progress);  // Gauss–Newton
  out.status = run.status;
  out.success = run.success;
  out.iterations = run.iterations;
  out.evaluations = run.evaluations;
  out.evaluation_seconds = run.evaluation_seconds;
  out.log_scales = run.final_point.size() ? run.final_point : out.start_log_scales;
  try {
    out.final = objective.evaluate(out.log_scales, false);
  } catch (const std::runtime_error& e) {
    out.success = false;
    out.status += std::string(" (final point unusable: ") + e.what() + ")";
  }
  out.seconds = t0.seconds();
  return out;
}

}  // namespace spinesim::calibration
