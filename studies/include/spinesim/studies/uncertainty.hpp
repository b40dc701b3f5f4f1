// Uncertainty propagated through a model from measured windows: a sample of the inputs' ranges
// (a Latin hypercube: the prior, uniform over each range) is weighted by how well each point's
// outputs fall in the windows, and the weighted sample is the inputs and outputs the
// measurements allow (importance weights of the posterior; Smith & Gelfand 1992).
//
// A window [low, high] is read as a log-normal measurement, mean ± 1 SD on the log scale: the
// residual is calibration::window_residual's r = ln(q / √(low·high)) / (½ ln(high/low)), the same
// as the identification's, and a point's likelihood is exp(−½ Σ r²). The weights' effective
// sample size, (Σw)² / Σw² (Kish 1965), says how many points carry the answer: a few means the
// sample is too coarse where the windows are, or that no part of the ranges meets them.
#pragma once

#include "spinesim/calibration/window_fit.hpp"
#include "spinesim/studies/sweep_plan.hpp"

#include <nlohmann/json.hpp>

#include <vector>

namespace spinesim::studies {

struct SampleWeights {
  std::vector<double> weights;  ///< per point, summing to 1; 0 where an output is missing
  int used = 0;                 ///< points with every windowed output a positive number
  double effective_size = 0;    ///< (Σw)² / Σw²
  double best_misfit = 0;       ///< the smallest ½ Σ r² over the points used
};

/// The likelihood weights of the points: quantities[i][j] is point i's value of window j's
/// output (NaN: missing; a point missing any is left out). Throws std::invalid_argument for a
/// bad window or when no point has all of them.
SampleWeights window_weights(const std::vector<std::vector<double>>& quantities,
                             const std::vector<calibration::WindowTarget>& windows);

struct WeightedSummary {
  double mean = 0, sd = 0;
  double q05 = 0, q50 = 0, q95 = 0;  ///< weighted quantiles
};

/// Mean, standard deviation and the 5, 50 and 95 % quantiles of `values` under `weights`
/// (non-negative, not all 0; NaN values with weight 0 are skipped). Quantiles interpolate
/// between the values at their cumulative weights' midpoints, so equal weights give the sample's
/// usual (Hazen) quantiles.
WeightedSummary weighted_summary(const std::vector<double>& values,
                                 const std::vector<double>& weights);

/// For a plan with windows (null otherwise): each point's weight (uncertainty.hpp
/// window_weights), the effective sample size, and for every parameter and numeric output its
/// summary under equal weights ("prior") and under the weights ("posterior"): {"mean", "sd",
/// "q05", "q50", "q95"}. Points that failed or miss a windowed output weigh 0 (counted).
nlohmann::json sweep_uncertainty(const SweepPlan& plan, const std::vector<SweepPoint>& points,
                                 const std::vector<nlohmann::json>& outputs);

}  // namespace spinesim::studies
