// Window weights against an analytic posterior: a log-normal measurement of exp(x) with x uniform
// over a wide range leaves x normal, so its weighted mean, SD, quantiles and the effective sample
// size are known in closed form, and a linear function of x carries them over. Equal weights
// give the sample's own summary.
#include "spinesim/studies/uncertainty.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace st = spinesim::studies;

// x uniform on [−5, 5] (stratified, N points), q = exp(x) measured in [e^−1, e^1]: r = x, so the
// weights are a standard normal's density and the posterior of x is N(0, 1) (truncated at ±5σ).
// ESS / N = (∫φ)² / (10 ∫φ²) = 2π / (10 √π) = 0.3545.
TEST(Uncertainty, ALogNormalWindowLeavesTheAnalyticPosterior) {
  const int n = 4000;
  std::vector<std::vector<double>> q;
  std::vector<double> x, z;
  for (int i = 0; i < n; ++i) {
    x.push_back(-5 + 10 * (i + 0.5) / n);
    z.push_back(2 * x.back() + 1);
    q.push_back({std::exp(x.back())});
  }
  const st::SampleWeights w = st::window_weights(q, {{"q", std::exp(-1.0), std::exp(1.0)}});
  EXPECT_EQ(w.used, n);
  EXPECT_NEAR(w.best_misfit, 0, 1e-5);
  EXPECT_NEAR(w.effective_size / n, 2 * M_PI / (10 * std::sqrt(M_PI)), 0.005);
  const st::WeightedSummary sx = st::weighted_summary(x, w.weights);
  EXPECT_NEAR(sx.mean, 0, 1e-6);
  EXPECT_NEAR(sx.sd, 1, 1e-3);
  EXPECT_NEAR(sx.q05, -1.6449, 5e-3);
  EXPECT_NEAR(sx.q50, 0, 5e-3);
  EXPECT_NEAR(sx.q95, 1.6449, 5e-3);
  const st::WeightedSummary sz = st::weighted_summary(z, w.weights);  // carried through 2x + 1
  EXPECT_NEAR(sz.mean, 1, 1e-6);
  EXPECT_NEAR(sz.sd, 2, 2e-3);
  EXPECT_NEAR(sz.q95, 1 + 2 * 1.6449, 1e-2);
  // The prior (equal weights) is the uniform's: SD 10/√12.
  const st::WeightedSummary px = st::weighted_summary(x, std::vector<double>(x.size(), 1.0));
  EXPECT_NEAR(px.sd, 10 / std::sqrt(12.0), 1e-3);
}

// Two windows multiply: q1 = exp(x) in [e^−1, e^1] and q2 = exp(x) in [e^0, e^2] give a posterior
// N(½, ½); a point missing a value is left out, with weight 0.
TEST(Uncertainty, WindowsCombineAndMissingPointsAreLeftOut) {
  const int n = 4001;
  std::vector<std::vector<double>> q;
  std::vector<double> x;
  for (int i = 0; i < n; ++i) {
    x.push_back(-5 + 10 * (i + 0.5) / n);
    q.push_back({std::exp(x.back()),
                 i == 7 ? std::numeric_limits<double>::quiet_NaN() : std::exp(x.back())});
  }
  const st::SampleWeights w =
      st::window_weights(q, {{"a", std::exp(-1.0), std::exp(1.0)}, {"b", 1.0, std::exp(2.0)}});
  EXPECT_EQ(w.used, n - 1);
  EXPECT_EQ(w.weights[7], 0);
  const st::WeightedSummary s = st::weighted_summary(x, w.weights);
  EXPECT_NEAR(s.mean, 0.5, 1e-4);
  EXPECT_NEAR(s.sd, std::sqrt(0.5), 1e-3);
  EXPECT_THROW(st::window_weights(q, {{"bad", 2.0, 1.0}, {"b", 1.0, 2.0}}), std::invalid_argument);
  EXPECT_THROW(st::window_weights({{-1.0}}, {{"a", 1.0, 2.0}}), std::invalid_argument);
}

// Equal weights: the sample's mean, population SD and Hazen quantiles ((i + ½) / n).
TEST(Uncertainty, EqualWeightsGiveTheSamplesOwnSummary) {
  std::vector<double> v;
  for (int i = 20; i >= 1; --i) v.push_back(i);  // order does not matter
  const st::WeightedSummary s = st::weighted_summary(v, std::vector<double>(20, 0.25));
  EXPECT_DOUBLE_EQ(s.mean, 10.5);
  EXPECT_NEAR(s.sd, std::sqrt((20.0 * 20.0 - 1) / 12), 1e-12);
  EXPECT_NEAR(s.q05, 1.5, 1e-12);
  EXPECT_NEAR(s.q50, 10.5, 1e-12);
  EXPECT_NEAR(s.q95, 19.5, 1e-12);
  EXPECT_THROW(st::weighted_summary(v, std::vector<double>(20, 0.0)), std::invalid_argument);
}
