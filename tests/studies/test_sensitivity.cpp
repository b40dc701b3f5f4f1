// Sensitivity estimators against analytic answers: Morris effects of a linear model are its
// slopes with no spread, an interaction spreads them; Sobol indices of an additive model are its
// variance shares, and of the Ishigami function (Ishigami & Homma 1990) its analytic indices.
#include "spinesim/studies/sensitivity.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace st = spinesim::studies;

namespace {

/// The inputs' ranges mapped from the unit cube.
std::vector<double> mapped(const std::vector<double>& u, const std::vector<double>& from,
                           const std::vector<double>& to) {
  std::vector<double> x(u.size());
  for (std::size_t i = 0; i < u.size(); ++i) x[i] = from[i] + u[i] * (to[i] - from[i]);
  return x;
}

}  // namespace

TEST(Morris, TrajectoriesMoveOneInputByDeltaOnTheGrid) {
  const int k = 5, r = 12, p = 6;
  const st::UnitPoints d = st::morris_design(k, r, p, 3);
  ASSERT_EQ(d.size(), std::size_t(r * (k + 1)));
  const double delta = p / (2.0 * (p - 1));
  for (std::size_t t = 0; t < d.size(); t += k + 1) {
    std::vector<int> moved(k, 0);
    for (int j = 1; j <= k; ++j) {
      int changes = 0;
      for (int i = 0; i < k; ++i) {
        const double step = d[t + j][std::size_t(i)] - d[t + j - 1][std::size_t(i)];
        if (step != 0) {
          ++changes, ++moved[std::size_t(i)];
          EXPECT_NEAR(std::abs(step), delta, 1e-15);
        }
      }
      EXPECT_EQ(changes, 1);
    }
    for (int i = 0; i < k; ++i) EXPECT_EQ(moved[std::size_t(i)], 1);  // each input once
    for (const auto& row :
         std::vector<std::vector<double>>(d.begin() + long(t), d.begin() + long(t + k + 1)))
      for (double v : row) {
        EXPECT_GE(v, -1e-15);
        EXPECT_LE(v, 1 + 1e-15);
        const double level = v * (p - 1);
        EXPECT_NEAR(level, std::round(level), 1e-12);  // on the p-level grid
      }
  }
  EXPECT_THROW(st::morris_design(k, r, 5, 3), std::invalid_argument);
}

TEST(Morris, ALinearModelsEffectsAreItsSlopesAndAnInteractionSpreadsThem) {
  const std::vector<double> from = {0, 10, -1}, to = {2, 30, 1}, slope = {3, -0.5, 7};
  const std::vector<double> span = {2, 20, 2};
  const st::UnitPoints d = st::morris_design(3, 20, 4, 9);
  std::vector<double> linear, mixed;
  for (const auto& u : d) {
    const auto x = mapped(u, from, to);
    linear.push_back(slope[0] * x[0] + slope[1] * x[1] + slope[2] * x[2]);
    mixed.push_back(x[0] * x[2] + slope[1] * x[1]);
  }
  const auto e = st::morris_effects(d, linear, span);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(e[i].mu, slope[i], 1e-9);
    EXPECT_NEAR(e[i].mu_star, std::abs(slope[i]), 1e-9);
    EXPECT_NEAR(e[i].sigma, 0, 1e-9);
  }
  const auto m = st::morris_effects(d, mixed, span);
  EXPECT_GT(m[0].sigma, 0.1);  // x0's effect is x2: it varies with x2
  EXPECT_GT(m[2].sigma, 0.1);
  EXPECT_NEAR(m[1].sigma, 0, 1e-9);  // x1 is additive
  EXPECT_NEAR(m[1].mu, slope[1], 1e-9);
}

// An additive model's first and total indices are equal, its variance shares c_i² Var(x_i) / V.
TEST(Sobol, AnAdditiveModelsIndicesAreItsVarianceShares) {
  const std::vector<double> c = {1, 2, 0.5};
  const st::UnitPoints d = st::saltelli_design(3, 1 << 14, 5);
  ASSERT_EQ(d.size(), std::size_t((1 << 14) * 5));
  std::vector<double> y;
  for (const auto& u : d) y.push_back(c[0] * u[0] + c[1] * u[1] + c[2] * u[2]);
  const auto s = st::sobol_indices(3, y);
  const double v = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / 12;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(s[i].first, c[i] * c[i] / 12 / v, 0.02) << i;
    EXPECT_NEAR(s[i].total, c[i] * c[i] / 12 / v, 0.02) << i;
  }
  EXPECT_THROW(st::sobol_indices(3, std::vector<double>(d.size(), 1.0)), std::invalid_argument);
  EXPECT_THROW(st::sobol_indices(4, y), std::invalid_argument);
}

// Ishigami: f = sin x1 + a sin² x2 + b x3⁴ sin x1 on [−π, π]³ (a = 7, b = 0.1). Analytic:
// V1 = (1 + bπ⁴/5)²/2, V2 = a²/8, V13 = 8b²π⁸/225, V = V1 + V2 + V13; S3 = 0.
TEST(Sobol, TheIshigamiFunctionsIndicesAreTheAnalyticOnes) {
  const double a = 7, b = 0.1, pi = M_PI;
  const double v1 = 0.5 * std::pow(1 + b * std::pow(pi, 4) / 5, 2), v2 = a * a / 8,
               v13 = 8 * b * b * std::pow(pi, 8) / 225, v = v1 + v2 + v13;
  const st::UnitPoints d = st::saltelli_design(3, 1 << 14, 17);
  std::vector<double> y;
  for (const auto& u : d) {
    const auto x = mapped(u, {-pi, -pi, -pi}, {pi, pi, pi});
    y.push_back(std::sin(x[0]) + a * std::pow(std::sin(x[1]), 2) +
                b * std::pow(x[2], 4) * std::sin(x[0]));
  }
  const auto s = st::sobol_indices(3, y);
  EXPECT_NEAR(s[0].first, v1 / v, 0.03);
  EXPECT_NEAR(s[1].first, v2 / v, 0.03);
  EXPECT_NEAR(s[2].first, 0, 0.03);
  EXPECT_NEAR(s[0].total, (v1 + v13) / v, 0.03);
  EXPECT_NEAR(s[1].total, v2 / v, 0.03);
  EXPECT_NEAR(s[2].total, v13 / v, 0.03);
  // The published values (Saltelli et al. 2010's test case) for the record.
  EXPECT_NEAR(v1 / v, 0.3139, 5e-4);
  EXPECT_NEAR((v1 + v13) / v, 0.5576, 5e-4);
  EXPECT_NEAR(v13 / v, 0.2437, 5e-4);
}

// A linear model's effects do not vary, so every resample gives them and the intervals close on
// them; where effects vary (an interaction) the interval holds the estimate and narrows as
// 1/√r with the number of trajectories.
TEST(Morris, BootstrapIntervalsCloseOnALinearModelAndNarrowAsOneOverRootR) {
  const std::vector<double> from = {0, 10, -1}, to = {2, 30, 1}, span = {2, 20, 2};
  auto run = [&](int r, bool mixed) {
    const st::UnitPoints d = st::morris_design(3, r, 4, 21);
    std::vector<double> y;
    for (const auto& u : d) {
      const auto x = mapped(u, from, to);
      y.push_back(mixed ? x[0] * x[2] - 0.5 * x[1] : 3 * x[0] - 0.5 * x[1] + 7 * x[2]);
    }
    return std::make_pair(st::morris_effects(d, y, span),
                          st::morris_bootstrap(d, y, span, 400, 0.9, 5));
  };
  const auto [e, ci] = run(20, false);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(ci[i].mu_star.low, e[i].mu_star, 1e-9);
    EXPECT_NEAR(ci[i].mu_star.high, e[i].mu_star, 1e-9);
    EXPECT_NEAR(ci[i].sigma.high, 0, 1e-9);
  }
  const auto [e20, ci20] = run(20, true);
  const auto [e320, ci320] = run(320, true);
  for (const auto& [ee, cc] : {std::make_pair(e20, ci20), std::make_pair(e320, ci320)}) {
    EXPECT_LE(cc[0].mu_star.low, ee[0].mu_star);
    EXPECT_GE(cc[0].mu_star.high, ee[0].mu_star);
  }
  const double w20 = ci20[0].mu_star.high - ci20[0].mu_star.low;
  const double w320 = ci320[0].mu_star.high - ci320[0].mu_star.low;
  EXPECT_GT(w20, 0);
  EXPECT_NEAR(w320 / w20, 0.25, 0.1);  // 1/√16
  EXPECT_THROW(st::morris_bootstrap(st::morris_design(3, 4, 4, 1), std::vector<double>(12, 0.0),
                                    span, 5, 0.9, 1),
               std::invalid_argument);
}

// Coverage: over independent replicates of the Ishigami study, the 90 % bootstrap intervals hold
// the analytic indices about 90 % of the time (the percentile bootstrap is approximate at
// small N, so the check allows 75 … 98 %).
TEST(Sobol, BootstrapIntervalsCoverTheIshigamiIndicesAtAboutTheirConfidence) {
  const double a = 7, b = 0.1, pi = M_PI;
  const double v1 = 0.5 * std::pow(1 + b * std::pow(pi, 4) / 5, 2), v2 = a * a / 8,
               v13 = 8 * b * b * std::pow(pi, 8) / 225, v = v1 + v2 + v13;
  const double first[3] = {v1 / v, v2 / v, 0}, total[3] = {(v1 + v13) / v, v2 / v, v13 / v};
  const int replicates = 200;
  int covered_first[3] = {0, 0, 0}, covered_total[3] = {0, 0, 0};
  for (int r = 0; r < replicates; ++r) {
    const st::UnitPoints d = st::saltelli_design(3, 512, 1000 + std::uint64_t(r));
    std::vector<double> y;
    for (const auto& u : d) {
      const auto x = mapped(u, {-pi, -pi, -pi}, {pi, pi, pi});
      y.push_back(std::sin(x[0]) + a * std::pow(std::sin(x[1]), 2) +
                  b * std::pow(x[2], 4) * std::sin(x[0]));
    }
    const auto ci = st::sobol_bootstrap(3, y, 200, 0.9, 7 + std::uint64_t(r));
    for (int i = 0; i < 3; ++i) {
      covered_first[i] +=
          ci[std::size_t(i)].first.low <= first[i] && first[i] <= ci[std::size_t(i)].first.high;
      covered_total[i] +=
          ci[std::size_t(i)].total.low <= total[i] && total[i] <= ci[std::size_t(i)].total.high;
    }
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(covered_first[i], 0.75 * replicates) << "S" << i + 1;
    EXPECT_LE(covered_first[i], 0.98 * replicates) << "S" << i + 1;
    EXPECT_GE(covered_total[i], 0.75 * replicates) << "ST" << i + 1;
    EXPECT_LE(covered_total[i], 0.98 * replicates) << "ST" << i + 1;
  }
  std::printf("coverage of the 90 %% intervals, S1 S2 S3 ST1 ST2 ST3: %d %d %d %d %d %d of %d\n",
              covered_first[0], covered_first[1], covered_first[2], covered_total[0],
              covered_total[1], covered_total[2], replicates);
}
