#include "spinesim/studies/uncertainty.hpp"

#include "spinesim/studies/sweep_plan.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace spinesim::studies {

SampleWeights window_weights(const std::vector<std::vector<double>>& quantities,
                             const std::vector<calibration::WindowTarget>& windows) {
  for (const auto& w : windows)
    if (!(w.low > 0 && w.high > w.low && std::isfinite(w.high)))
      throw std::invalid_argument("window '" + w.name + "': give 0 < low < high");
  if (windows.empty()) throw std::invalid_argument("uncertainty: no window");
  SampleWeights out;
  std::vector<double> misfit(quantities.size(), std::numeric_limits<double>::quiet_NaN());
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < quantities.size(); ++i) {
    if (quantities[i].size() != windows.size())
      throw std::invalid_argument("uncertainty: one value per window at every point");
    double sum = 0;
    for (std::size_t j = 0; j < windows.size(); ++j) {
      const double r = calibration::window_residual(quantities[i][j], windows[j]);
      sum += 0.5 * r * r;
    }
    if (!std::isfinite(sum)) continue;  // missing or non-positive: left out
    misfit[i] = sum;
    best = std::min(best, sum);
    ++out.used;
  }
  if (out.used == 0)
    throw std::invalid_argument("uncertainty: no point has a positive number for every window");
  out.best_misfit = best;
  out.weights.assign(quantities.size(), 0.0);
  double total = 0;
  for (std::size_t i = 0; i < misfit.size(); ++i)
    if (std::isfinite(misfit[i])) total += out.weights[i] = std::exp(best - misfit[i]);
  double squares = 0;
  for (double& w : out.weights) w /= total, squares += w * w;
  out.effective_size = 1 / squares;
  return out;
}

WeightedSummary weighted_summary(const std::vector<double>& values,
                                 const std::vector<double>& weights) {
  if (values.size() != weights.size())
    throw std::invalid_argument("weighted_summary: one weight per value");
  std::vector<std::pair<double, double>> vw;
  double total = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!(weights[i] >= 0)) throw std::invalid_argument("weighted_summary: a negative weight");
    if (weights[i] == 0) continue;
    if (!std::isfinite(values[i]))
      throw std::invalid_argument("weighted_summary: a weighted value is not a number");
    vw.emplace_back(values[i], weights[i]);
    total += weights[i];
  }
  if (vw.empty()) throw std::invalid_argument("weighted_summary: every weight is 0");
  std::sort(vw.begin(), vw.end());
  WeightedSummary s;
  for (const auto& [v, w] : vw) s.mean += v * w / total;
  for (const auto& [v, w] : vw) s.sd += (v - s.mean) * (v - s.mean) * w / total;
  s.sd = std::sqrt(s.sd);
  // Midpoints of the cumulative weights: the i-th of n equal weights sits at (i + ½) / n.
  std::vector<double> at(vw.size());
  double running = 0;
  for (std::size_t i = 0; i < vw.size(); ++i) {
    at[i] = (running + 0.5 * vw[i].second) / total;
    running += vw[i].second;
  }
  auto quantile = [&](double q) {
    if (q <= at.front()) return vw.front().first;
    if (q >= at.back()) return vw.back().first;
    const std::size_t hi = std::size_t(std::upper_bound(at.begin(), at.end(), q) - at.begin());
    const std::size_t lo = hi - 1;
    const double t = (q - at[lo]) / (at[hi] - at[lo]);
    return vw[lo].first + t * (vw[hi].first - vw[lo].first);
  };
  s.q05 = quantile(0.05), s.q50 = quantile(0.5), s.q95 = quantile(0.95);
  return s;
}

namespace {

nlohmann::json summary_json(const WeightedSummary& s) {
  return {{"mean", s.mean}, {"sd", s.sd}, {"q05", s.q05}, {"q50", s.q50}, {"q95", s.q95}};
}

double number_or_nan(const nlohmann::json& o, const std::string& key) {
  const nlohmann::json v = o.is_object() ? o.value(key, nlohmann::json()) : nlohmann::json();
  return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

nlohmann::json sweep_uncertainty(const SweepPlan& plan, const std::vector<SweepPoint>& points,
                                 const std::vector<nlohmann::json>& outputs) {
  using nlohmann::json;
  if (plan.windows.empty()) return nullptr;
  if (outputs.size() != points.size())
    throw std::invalid_argument("sweep_uncertainty: one output object per point");
  std::vector<std::vector<double>> measured;
  for (const auto& o : outputs) {
    measured.emplace_back();
    for (const auto& w : plan.windows) measured.back().push_back(number_or_nan(o, w.name));
  }
  json out = {{"method",
               "Latin hypercube weighted by the windows' likelihood exp(-sum r^2 / 2), r = "
               "ln(q / sqrt(low high)) / (ln(high / low) / 2)"},
              {"points", points.size()}};
  json windows = json::object();
  for (std::size_t j = 0; j < plan.windows.size(); ++j)
    windows[plan.windows[j].name] = {{"low", plan.windows[j].low},
                                     {"high", plan.windows[j].high},
                                     {"source", plan.window_sources[j]}};
  out["windows"] = windows;
  SampleWeights w;
  try {
    w = window_weights(measured, plan.windows);
  } catch (const std::invalid_argument& e) {
    out["error"] = e.what();
    return out;
  }
  out["points_used"] = w.used;
  out["effective_sample_size"] = w.effective_size;
  out["best_misfit"] = w.best_misfit;
  out["weights"] = w.weights;
  std::vector<double> prior(points.size(), 0.0);
  for (std::size_t i = 0; i < points.size(); ++i) prior[i] = w.weights[i] > 0 ? 1.0 : 0.0;
  // The prior over the same points as the posterior: a comparison of like with like.
  auto summarise = [&](const std::vector<double>& v) -> json {
    std::vector<double> wp = prior, wq = w.weights;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!std::isfinite(v[i])) wp[i] = wq[i] = 0;
    if (std::none_of(wq.begin(), wq.end(), [](double x) { return x > 0; }))
      return {{"error", "no weighted point has a number"}};
    return {{"prior", summary_json(weighted_summary(v, wp))},
            {"posterior", summary_json(weighted_summary(v, wq))}};
  };
  json parameters = json::object(), quantities = json::object();
  for (const auto& p : plan.parameters) {
    std::vector<double> v;
    for (const auto& point : points) v.push_back(number_or_nan(point.values, p.option));
    parameters[p.option] = summarise(v);
  }
  for (const auto& [column, pointer] : plan.outputs) {
    std::vector<double> v;
    for (const auto& o : outputs) v.push_back(number_or_nan(o, column));
    quantities[column] = summarise(v);
  }
  out["parameters"] = parameters;
  out["outputs"] = quantities;
  return out;
}

}  // namespace spinesim::studies
