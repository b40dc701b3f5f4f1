#include "spinesim/calibration/window_fit.hpp"

#include "spinesim/common/parallel.hpp"
#include "spinesim/common/timer.hpp"

#include "bounded_nlp.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration {

namespace {

void check_parameters(const std::vector<FitParameter>& parameters,
                      const WindowFitOptions& options) {
  if (parameters.empty()) throw std::invalid_argument("identification: no parameter to fit");
  for (const FitParameter& p : parameters) {
    const bool finite = std::isfinite(p.lower) && std::isfinite(p.upper) && std::isfinite(p.start);
    if (!finite || !(p.lower > 0) || !(p.lower < p.upper))
      throw std::invalid_argument("identification: parameter '" + p.name +
                                  "' needs finite bounds 0 < lower < upper");
    if (p.start < p.lower || p.start > p.upper)
      throw std::invalid_argument("identification: parameter '" + p.name +
                                  "' starts outside its bounds");
  }
  if (!(options.log_step > 0) || !(options.log_step < 1) || options.threads < 1)
    throw std::invalid_argument("identification: step in (0, 1) and threads >= 1 expected");
  validate_stopping(options.ipopt);
}

void check(const std::vector<FitParameter>& parameters, const std::vector<WindowTarget>& targets,
           const std::vector<bool>& used, const WindowFitOptions& options) {
  check_parameters(parameters, options);
  for (const WindowTarget& t : targets)
    if (!std::isfinite(t.low) || !std::isfinite(t.high) || !(t.low > 0) || !(t.low < t.high))
      throw std::invalid_argument("identification: target '" + t.name +
                                  "' needs a window 0 < low < high");
  if (used.size() != targets.size())
    throw std::invalid_argument("identification: one 'used' flag per target expected");
  bool any = false;
  for (bool u : used) any = any || u;
  if (!any) throw std::invalid_argument("identification: no target in use (empty data set)");
}

/// The model at each of `points` (ln p), on `threads` threads.
std::vector<Eigen::VectorXd> evaluate_all(const ResidualModel& model,
                                          const std::vector<Eigen::VectorXd>& points, int threads) {
  std::vector<Eigen::VectorXd> out(points.size());
  parallel_for(points.size(), threads,
               [&](std::size_t k) { out[k] = model(points[k].array().exp().matrix()); });
  return out;
}

Eigen::VectorXd residuals(const Eigen::VectorXd& q, const std::vector<WindowTarget>& targets) {
  Eigen::VectorXd r(q.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) r(i) = window_residual(q(i), targets[size_t(i)]);
  return r;
}

}  // namespace

double window_residual(double quantity, const WindowTarget& t) {
  if (!(quantity > 0)) return std::numeric_limits<double>::quiet_NaN();
  return std::log(quantity / std::sqrt(t.low * t.high)) / (0.5 * std::log(t.high / t.low));
}

namespace {

/// fit_least_squares, with the final residuals left to the caller when `residuals_at_end` is
/// false (fit_to_windows evaluates its model there itself).
LeastSquaresFit least_squares(const ResidualModel& model,
                              const std::vector<FitParameter>& parameters,
                              const WindowFitOptions& options, const Progress& progress,
                              bool residuals_at_end) {
  const Timer timer;
  const Eigen::Index n = Eigen::Index(parameters.size());
  Eigen::VectorXd lower(n), upper(n), start(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    lower(j) = std::log(parameters[size_t(j)].lower);
    upper(j) = std::log(parameters[size_t(j)].upper);
    start(j) = std::log(parameters[size_t(j)].start);
  }
  std::atomic<int> evaluations{0};
  const detail::NlpFunction f = [&](const Eigen::VectorXd& y) {
    // The point and one forward step per unknown, inward where y sits on its upper bound.
    std::vector<Eigen::VectorXd> points(std::size_t(n + 1), y);
    Eigen::VectorXd step(n);
    for (Eigen::Index j = 0; j < n; ++j) {
      step(j) = y(j) + options.log_step > upper(j) ? -options.log_step : options.log_step;
      points[std::size_t(j + 1)](j) += step(j);
    }
    const std::vector<Eigen::VectorXd> r = evaluate_all(model, points, options.threads);
    evaluations += int(points.size());
    const Eigen::VectorXd& r0 = r[0];
    Eigen::MatrixXd jac(r0.size(), n);
    for (Eigen::Index j = 0; j < n; ++j) {
      if (r[std::size_t(j + 1)].size() != r0.size())
        throw std::logic_error("least squares: the model's residual changed length");
      jac.col(j) = (r[std::size_t(j + 1)] - r0) / step(j);
    }
    if (!r0.allFinite() || !jac.allFinite())
      throw std::runtime_error("the model gives no value here");  // Ipopt shortens the step
    detail::NlpValues v;
    v.value = 0.5 * r0.squaredNorm();
    v.gradient = jac.transpose() * r0;
    v.hessian = jac.transpose() * jac;
    return v;
  };
  const detail::NlpRun run = detail::run_bounded_nlp(
      f, start, lower, upper, detail::HessianKind::dense, options.ipopt, progress);
  LeastSquaresFit out;
  out.success = run.success && run.final_point.size() == n;
  out.status = run.status;
  out.iterations = run.iterations;
  const Eigen::VectorXd y = run.final_point.size() == n ? run.final_point : start;
  out.parameters = y.array().exp().matrix();
  out.model_evaluations = evaluations;
  if (residuals_at_end) {
    out.residuals = model(out.parameters);
    out.model_evaluations += 1;
    out.objective = 0.5 * out.residuals.squaredNorm();
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const FitParameter& p = parameters[size_t(j)];
    const auto say = [&](const char* side, double bound) {
      std::ostringstream s;
      s << p.name << " at " << side << " bound (" << bound << (p.units.empty() ? "" : " ")
        << p.units << ")";
      out.active_bounds.push_back(s.str());
    };
    if (y(j) - lower(j) < options.bound_tolerance) say("lower", p.lower);
    if (upper(j) - y(j) < options.bound_tolerance) say("upper", p.upper);
  }
  out.seconds = timer.seconds();
  return out;
}

}  // namespace

LeastSquaresFit fit_least_squares(const ResidualModel& model,
                                  const std::vector<FitParameter>& parameters,
                                  const WindowFitOptions& options, const Progress& progress) {
  check_parameters(parameters, options);
  return least_squares(model, parameters, options, progress, true);
}

WindowFit fit_to_windows(const QuantityModel& model, const std::vector<FitParameter>& parameters,
                         const std::vector<WindowTarget>& targets, const std::vector<bool>& used,
                         const WindowFitOptions& options, const Progress& progress) {
  check(parameters, targets, used, options);
  Eigen::VectorXd mask(Eigen::Index(targets.size()));
  for (std::size_t i = 0; i < targets.size(); ++i) mask(Eigen::Index(i)) = used[i] ? 1.0 : 0.0;
  const ResidualModel masked = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    return residuals(model(p), targets).cwiseProduct(mask);
  };
  const LeastSquaresFit fit = least_squares(masked, parameters, options, progress, false);
  WindowFit out;
  out.success = fit.success;
  out.status = fit.status;
  out.iterations = fit.iterations;
  out.parameters = fit.parameters;
  out.quantities = model(out.parameters);
  out.model_evaluations = fit.model_evaluations + 1;
  out.residuals = residuals(out.quantities, targets);
  out.objective = 0.5 * out.residuals.cwiseProduct(mask).squaredNorm();
  out.active_bounds = fit.active_bounds;
  out.seconds = fit.seconds;  // without the last model run, as before
  return out;
}

std::vector<WindowFit> leave_one_out(const QuantityModel& model,
                                     const std::vector<FitParameter>& parameters,
                                     const std::vector<WindowTarget>& targets,
                                     const std::vector<bool>& used, const WindowFitOptions& options,
                                     const std::function<void(int target)>& before,
                                     const std::function<void(int, const WindowFit&)>& after) {
  std::vector<WindowFit> out(targets.size());
  for (std::size_t i = 0; i < targets.size() && i < used.size(); ++i) {
    if (!used[i]) continue;
    std::vector<bool> others = used;
    others[i] = false;
    if (std::find(others.begin(), others.end(), true) == others.end()) continue;  // nothing left
    if (before) before(int(i));
    out[i] = fit_to_windows(model, parameters, targets, others, options);
    if (after) after(int(i), out[i]);
  }
  return out;
}

}  // namespace spinesim::calibration
