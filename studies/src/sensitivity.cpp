#include "spinesim/studies/sensitivity.hpp"

#include "spinesim/studies/sweep_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace spinesim::studies {
namespace {

std::size_t below(SplitMix64& rng, std::size_t n) { return std::size_t(rng.next() % n); }

void check_bootstrap(int resamples, double confidence) {
  if (resamples < 10 || !(confidence > 0 && confidence < 1))
    throw std::invalid_argument(
        "bootstrap: give at least 10 resamples and a confidence between 0 and 1");
}

/// The percentile interval of `v` (sorted here) at `confidence`, by linear interpolation between
/// order statistics.
Interval percentile_interval(std::vector<double> v, double confidence) {
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    const double pos = q * double(v.size() - 1);
    const std::size_t lo = std::size_t(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (pos - double(lo)) * (v[hi] - v[lo]);
  };
  return {at((1 - confidence) / 2), at((1 + confidence) / 2)};
}

/// Each input's elementary effects, one per trajectory: effects[i][t].
std::vector<std::vector<double>> elementary_effects(const UnitPoints& design,
                                                    const std::vector<double>& y,
                                                    const std::vector<double>& span) {
  const std::size_t k = span.size();
  if (k == 0 || design.size() != y.size() || design.size() % (k + 1) != 0)
    throw std::invalid_argument("morris: the outputs do not match the design's trajectories");
  std::vector<std::vector<double>> effects(k);
  for (std::size_t t = 0; t < design.size(); t += k + 1)
    for (std::size_t j = 1; j <= k; ++j) {
      const auto& a = design[t + j - 1];
      const auto& b = design[t + j];
      std::size_t moved = k;
      for (std::size_t i = 0; i < k; ++i)
        if (a[i] != b[i]) moved = i;
      if (moved == k) throw std::invalid_argument("morris: a step moves no input");
      effects[moved].push_back((y[t + j] - y[t + j - 1]) / ((b[moved] - a[moved]) * span[moved]));
    }
  return effects;
}

/// μ, μ* and σ of the effects at trajectories `rows` (each input's effect t is trajectory t's).
MorrisEffect summarise(const std::vector<double>& e, const std::vector<std::size_t>& rows) {
  MorrisEffect out;
  const double n = double(rows.size());
  for (std::size_t t : rows) out.mu += e[t] / n, out.mu_star += std::abs(e[t]) / n;
  double ss = 0;
  for (std::size_t t : rows) ss += (e[t] - out.mu) * (e[t] - out.mu);
  out.sigma = rows.size() > 1 ? std::sqrt(ss / (n - 1)) : 0;
  return out;
}

/// Saltelli 2010's S_i and Jansen's S_Ti from the base rows `rows` of y (N (k + 2) values);
/// false when the output does not vary over those rows.
bool sobol_at(std::size_t k, const std::vector<double>& y, const std::vector<std::size_t>& rows,
              std::vector<SobolIndex>& out) {
  const std::size_t n = y.size() / (k + 2);
  const double* fa = y.data();
  const double* fb = y.data() + n;
  const double m = double(rows.size());
  double mean = 0;
  for (std::size_t j : rows) mean += (fa[j] + fb[j]) / (2 * m);
  double variance = 0;
  for (std::size_t j : rows)
    variance += ((fa[j] - mean) * (fa[j] - mean) + (fb[j] - mean) * (fb[j] - mean)) / (2 * m);
  if (!(variance > 0)) return false;
  out.assign(k, SobolIndex());
  for (std::size_t i = 0; i < k; ++i) {
    const double* fab = y.data() + (2 + i) * n;
    double first = 0, total = 0;
    for (std::size_t j : rows) {
      // f_B centred: the estimator's expectation does not depend on a shift of f, but its
      // variance grows with the mean (at a mean of 2.7 standard deviations, N = 2048: 0.81
      // for a share of 0.9; centred 0.90).
      first += (fb[j] - mean) * (fab[j] - fa[j]);
      total += (fa[j] - fab[j]) * (fa[j] - fab[j]);
    }
    out[i].first = first / m / variance;
    out[i].total = total / (2.0 * m) / variance;
  }
  return true;
}

std::size_t sobol_rows(int inputs, const std::vector<double>& y) {
  const std::size_t k = std::size_t(inputs);
  if (inputs < 1 || y.size() % (k + 2) != 0 || y.size() < 2 * (k + 2))
    throw std::invalid_argument("sobol: the outputs do not match a Saltelli design of " +
                                std::to_string(inputs) + " inputs");
  return y.size() / (k + 2);
}

std::vector<std::size_t> all_rows(std::size_t n) {
  std::vector<std::size_t> rows(n);
  std::iota(rows.begin(), rows.end(), std::size_t(0));
  return rows;
}

std::vector<std::size_t> resample(SplitMix64& rng, std::size_t n) {
  std::vector<std::size_t> rows(n);
  for (auto& r : rows) r = below(rng, n);
  return rows;
}

}  // namespace

UnitPoints morris_design(int inputs, int trajectories, int levels, std::uint64_t seed) {
  if (inputs < 1 || trajectories < 2 || levels < 4 || levels % 2 != 0)
    throw std::invalid_argument(
        "morris: give at least one input, two trajectories and an even number of levels >= 4");
  const std::size_t k = std::size_t(inputs);
  const double step = 1.0 / double(levels - 1);
  const double delta = double(levels) / (2.0 * double(levels - 1));
  SplitMix64 rng(seed);
  UnitPoints out;
  for (int t = 0; t < trajectories; ++t) {
    std::vector<double> x(k);
    std::vector<int> sign(k);
    for (std::size_t i = 0; i < k; ++i) {
      // A base level in the lower half, so that x and x + Δ are both on the grid in [0, 1].
      x[i] = double(below(rng, std::size_t(levels / 2))) * step;
      sign[i] = rng.next() & 1u ? 1 : -1;
      if (sign[i] < 0) x[i] += delta;  // a step down from the upper point
    }
    std::vector<std::size_t> order(k);
    std::iota(order.begin(), order.end(), std::size_t(0));
    for (std::size_t i = k - 1; i > 0; --i) std::swap(order[i], order[below(rng, i + 1)]);
    out.push_back(x);
    for (std::size_t i : order) {
      x[i] += sign[i] * delta;
      out.push_back(x);
    }
  }
  return out;
}

std::vector<MorrisEffect> morris_effects(const UnitPoints& design, const std::vector<double>& y,
                                         const std::vector<double>& span) {
  const auto effects = elementary_effects(design, y, span);
  std::vector<MorrisEffect> out;
  for (const auto& e : effects) out.push_back(summarise(e, all_rows(e.size())));
  return out;
}

std::vector<MorrisIntervals> morris_bootstrap(const UnitPoints& design,
                                              const std::vector<double>& y,
                                              const std::vector<double>& span, int resamples,
                                              double confidence, std::uint64_t seed) {
  check_bootstrap(resamples, confidence);
  const auto effects = elementary_effects(design, y, span);
  const std::size_t k = effects.size(), r = effects[0].size();
  std::vector<std::vector<double>> mu_star(k), mu(k), sigma(k);
  SplitMix64 rng(seed);
  for (int b = 0; b < resamples; ++b) {
    const auto rows = resample(rng, r);
    for (std::size_t i = 0; i < k; ++i) {
      const MorrisEffect e = summarise(effects[i], rows);
      mu_star[i].push_back(e.mu_star), mu[i].push_back(e.mu), sigma[i].push_back(e.sigma);
    }
  }
  std::vector<MorrisIntervals> out(k);
  for (std::size_t i = 0; i < k; ++i)
    out[i] = {percentile_interval(mu_star[i], confidence), percentile_interval(mu[i], confidence),
              percentile_interval(sigma[i], confidence)};
  return out;
}

UnitPoints saltelli_design(int inputs, int base_points, std::uint64_t seed) {
  if (inputs < 1 || base_points < 2)
    throw std::invalid_argument("sobol: give at least one input and two base points");
  const std::size_t k = std::size_t(inputs), n = std::size_t(base_points);
  SplitMix64 rng(seed);
  UnitPoints a(n, std::vector<double>(k)), b = a;
  for (auto* m : {&a, &b})
    for (auto& row : *m)
      for (double& v : row) v = rng.uniform();
  UnitPoints out = a;
  out.insert(out.end(), b.begin(), b.end());
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      std::vector<double> row = a[j];
      row[i] = b[j][i];
      out.push_back(std::move(row));
    }
  return out;
}

std::vector<SobolIndex> sobol_indices(int inputs, const std::vector<double>& y) {
  const std::size_t n = sobol_rows(inputs, y);
  std::vector<SobolIndex> out;
  if (!sobol_at(std::size_t(inputs), y, all_rows(n), out))
    throw std::invalid_argument("sobol: the output does not vary over the inputs' ranges");
  return out;
}

std::vector<SobolIntervals> sobol_bootstrap(int inputs, const std::vector<double>& y, int resamples,
                                            double confidence, std::uint64_t seed) {
  check_bootstrap(resamples, confidence);
  const std::size_t n = sobol_rows(inputs, y), k = std::size_t(inputs);
  std::vector<SobolIndex> s;
  if (!sobol_at(k, y, all_rows(n), s))
    throw std::invalid_argument("sobol: the output does not vary over the inputs' ranges");
  std::vector<std::vector<double>> first(k), total(k);
  SplitMix64 rng(seed);
  for (int b = 0, draws = 0; b < resamples;) {
    if (++draws > 100 * resamples)
      throw std::invalid_argument("sobol: the output varies at too few base rows to resample");
    if (!sobol_at(k, y, resample(rng, n), s)) continue;  // e.g. one row drawn n times
    for (std::size_t i = 0; i < k; ++i)
      first[i].push_back(s[i].first), total[i].push_back(s[i].total);
    ++b;
  }
  std::vector<SobolIntervals> out(k);
  for (std::size_t i = 0; i < k; ++i)
    out[i] = {percentile_interval(first[i], confidence), percentile_interval(total[i], confidence)};
  return out;
}

}  // namespace spinesim::studies
