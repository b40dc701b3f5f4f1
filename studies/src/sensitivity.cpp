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
  std::vector<MorrisEffect> out(k);
  for (std::size_t i = 0; i < k; ++i) {
    const auto& e = effects[i];
    const double n = double(e.size());
    for (double v : e) out[i].mu += v / n, out[i].mu_star += std::abs(v) / n;
    double ss = 0;
    for (double v : e) ss += (v - out[i].mu) * (v - out[i].mu);
    out[i].sigma = e.size() > 1 ? std::sqrt(ss / (n - 1)) : 0;
  }
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
  const std::size_t k = std::size_t(inputs);
  if (inputs < 1 || y.size() % (k + 2) != 0 || y.size() < 2 * (k + 2))
    throw std::invalid_argument("sobol: the outputs do not match a Saltelli design of " +
                                std::to_string(inputs) + " inputs");
  const std::size_t n = y.size() / (k + 2);
  const double* fa = y.data();
  const double* fb = y.data() + n;
  double mean = 0;
  for (std::size_t j = 0; j < 2 * n; ++j) mean += y[j] / double(2 * n);
  double variance = 0;
  for (std::size_t j = 0; j < 2 * n; ++j) variance += (y[j] - mean) * (y[j] - mean) / double(2 * n);
  if (!(variance > 0))
    throw std::invalid_argument("sobol: the output does not vary over the inputs' ranges");
  std::vector<SobolIndex> out(k);
  for (std::size_t i = 0; i < k; ++i) {
    const double* fab = y.data() + (2 + i) * n;
    double first = 0, total = 0;
    for (std::size_t j = 0; j < n; ++j) {
      // f_B centred: the estimator's expectation does not depend on a shift of f, but its
      // variance grows with the mean (at a mean of 2.7 standard deviations, N = 2048: 0.81
      // for a share of 0.9; centred 0.90).
      first += (fb[j] - mean) * (fab[j] - fa[j]);
      total += (fa[j] - fab[j]) * (fa[j] - fab[j]);
    }
    out[i].first = first / double(n) / variance;
    out[i].total = total / (2.0 * double(n)) / variance;
  }
  return out;
}

}  // namespace spinesim::studies
