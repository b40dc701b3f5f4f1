// Global sensitivity of a model's outputs to its inputs, from points a sweep ran.
//
// Morris screening (Morris 1991; μ* of Campolongo, Cariboni & Saltelli 2007): r trajectories on
// a p-level grid of the unit cube, each moving one input at a time by Δ = p / (2 (p − 1)); an
// input's elementary effect is the output's change over its step, in the output's units per the
// input's. μ* (the mean |effect|) ranks the inputs; σ (their spread) flags nonlinearity or
// interaction. k + 1 runs a trajectory.
//
// Sobol indices (Sobol 1993) by Saltelli's scheme (Saltelli et al. 2010): two independent
// samples A and B of N points and, for each input i, A with its column i taken from B; the
// first-order index S_i by Saltelli 2010's estimator, the total index S_Ti by Jansen's (1999).
// N (k + 2) runs. The indices are fractions of the output's variance: S_i what input i alone
// explains, S_Ti what it explains with all its interactions.
//
// Confidence intervals: the percentile bootstrap (Efron & Tibshirani 1993), resampling the
// independent units of each design with replacement: Morris's trajectories, Sobol's base rows
// (a row of A, its row of B and its k rows of A_B^i together; Archer, Saltelli & Sobol 1997).
// The interval says how far the finite sample leaves an index from the one an infinite sample
// of the same model would give; it says nothing of the model's own error.
//
// Inputs are given as ranges [from, to]; the designs are in the unit cube and mapped onto them.
// The random stream is the sweep's (SplitMix64), so a design and its intervals are the same on
// every machine.
#pragma once

#include <cstdint>
#include <vector>

namespace spinesim::studies {

/// A design's points in the unit cube: rows of k coordinates in [0, 1].
using UnitPoints = std::vector<std::vector<double>>;

/// Morris trajectories: r × (k + 1) points, trajectory t's rows t(k+1) … t(k+1)+k, each row
/// differing from the one before in one input by ±Δ. `levels` p even, >= 4.
UnitPoints morris_design(int inputs, int trajectories, int levels, std::uint64_t seed);

struct MorrisEffect {
  double mu = 0;       ///< mean elementary effect (output units per input unit)
  double mu_star = 0;  ///< mean |elementary effect|
  double sigma = 0;    ///< standard deviation of the elementary effects (n − 1)
};

/// The effects of each input from the outputs `y` at morris_design's points (same order);
/// `span[i]` is input i's range (to − from), so effects are per the input's own unit.
std::vector<MorrisEffect> morris_effects(const UnitPoints& design, const std::vector<double>& y,
                                         const std::vector<double>& span);

/// Saltelli's design: N (k + 2) points, in blocks of N: A, B, then A_B^1 … A_B^k (A with column
/// i from B). A and B are independent uniform samples.
UnitPoints saltelli_design(int inputs, int base_points, std::uint64_t seed);

struct SobolIndex {
  double first = 0;  ///< S_i
  double total = 0;  ///< S_Ti
};

/// The indices of each input from the outputs `y` at saltelli_design's points (same order).
/// Throws std::invalid_argument when the output does not vary (no variance to share).
std::vector<SobolIndex> sobol_indices(int inputs, const std::vector<double>& y);

/// A two-sided percentile interval.
struct Interval {
  double low = 0, high = 0;
};

struct MorrisIntervals {
  Interval mu_star, mu, sigma;
};

/// Percentile-bootstrap intervals of morris_effects' μ*, μ and σ at `confidence` (0 … 1), from
/// `resamples` (>= 10) resamples of the trajectories.
std::vector<MorrisIntervals> morris_bootstrap(const UnitPoints& design,
                                              const std::vector<double>& y,
                                              const std::vector<double>& span, int resamples,
                                              double confidence, std::uint64_t seed);

struct SobolIntervals {
  Interval first, total;
};

/// Percentile-bootstrap intervals of sobol_indices' S_i and S_Ti at `confidence`, from
/// `resamples` (>= 10) resamples of the N base rows. A resample whose output does not vary is
/// drawn again.
std::vector<SobolIntervals> sobol_bootstrap(int inputs, const std::vector<double>& y, int resamples,
                                            double confidence, std::uint64_t seed);

}  // namespace spinesim::studies
