// Private to fem/: the two pieces the hyperelastic Newton solvers share (hyperelastic_body.cpp,
// plate_newton.cpp) — the ramp of the load in increments that are halved when they fail, and
// the backtracking line search.
//
// The line search judges a step by the potential Π (energy minus the work of the loads) while Π
// can tell: Armijo's sufficient decrease Π(α) ≤ Π(0) + c α Π'(0). Near a solution the predicted
// decrease α Π'(0) ~ ‖r‖ ‖Δu‖ falls below the rounding noise of Π itself (a sum of tens of
// thousands of element energies, each formed from invariants like Ī1 − 3 that cancel), so
// Armijo then accepts or rejects at random and Newton stalls with a residual some orders above
// its tolerance. There the residual norm decides instead: a step is taken when ‖r‖ falls by the
// same fraction and Π does not rise above its rounding level. Far from the solution this never
// triggers — a step that raises Π measurably is always refused.
#pragma once

#include "spinesim/fem/hyperelastic_body.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace spinesim::fem::detail {

/// One point of a line search: the potential and the norm of the residual there (non-finite when
/// the state is inadmissible, e.g. an inverted element).
struct TrialPoint {
  double potential = 0;
  double residual = 0;
};

/// Relative rounding level of Π below which the residual decides (see above).
inline constexpr double kPotentialRounding = 1e-9;

/// Backtracks α = 1, ½, ¼, … ≥ alpha_min from `start` along a step with slope Π'(0) = `slope`;
/// `at(α)` evaluates the TrialPoint. `scale` is the size of the terms Π is made of (e.g.
/// max(|E|, |work|)). Returns the accepted α, or 0 when none is.
template <class At>
double backtrack(const TrialPoint& start, double slope, double scale, At&& at,
                 double alpha_min = 1e-8) {
  constexpr double c = 1e-4;
  const double rounding = kPotentialRounding * std::max(scale, std::abs(start.potential));
  for (double alpha = 1.0; alpha >= alpha_min; alpha *= 0.5) {
    const TrialPoint p = at(alpha);
    if (!std::isfinite(p.potential) || !std::isfinite(p.residual)) continue;
    if (slope < 0 && p.potential <= start.potential + c * alpha * slope) return alpha;
    if (p.potential <= start.potential + rounding && p.residual <= (1 - c * alpha) * start.residual)
      return alpha;
  }
  return 0;
}

/// Newton's convergence test for one increment: the last correction ‖Δu‖∞ within
/// tolerance · max(‖u‖∞, 1 mm) and the residual ‖r‖ within tolerance · max(‖f‖, 1 N) (f the
/// reaction) — or, once the correction has reached rounding (a thousandth of its tolerance, 1e-13
/// of the displacement by default), within a thousand times that. The second arm is the residual's
/// rounding floor: each element's pressure U'(J) carries K ε of rounding, so a nucleus with
/// K ≈ 1.7 GPa, elements of ~1–10 mm² and a thousand nodes leaves ‖r‖ ≈ 1e-10 N however exact
/// the state (measured on the structured L4-L5 disc: 1.1–2.9e-10 N, Newton corrections of 1e-14
/// mm, against a tolerance of 1e-10 N at a 0.5 N reaction).
inline bool increment_converged(double residual, double reaction, double correction, double size,
                                double tolerance) {
  const double r_tol = tolerance * std::max(reaction, 1.0);
  const double c_tol = tolerance * std::max(size, 1.0);
  if (correction > c_tol) return false;
  return residual <= r_tol || (correction <= 1e-3 * c_tol && residual <= 1e3 * r_tol);
}

/// Ramps the load fraction from 0 to 1 in options.load_increments equal steps; `increment(to)`
/// brings the state from the last converged fraction to `to` and returns whether it converged. A
/// failing increment is halved, at most options.max_cutbacks times in a row. Counts increments
/// and cutbacks in `sol`; returns "" or why the ramp stopped (`what` names the load).
template <class Increment>
std::string ramp(const NewtonOptions& options, HyperelasticSolution& sol, const std::string& what,
                 Increment&& increment) {
  double done = 0, size = 1.0 / options.load_increments;
  int cuts_in_a_row = 0;
  while (done < 1.0 - 1e-12) {
    const double to = std::min(1.0, done + size);
    if (increment(to)) {
      ++sol.increments, done = to, cuts_in_a_row = 0;
      continue;
    }
    if (++cuts_in_a_row > options.max_cutbacks)
      return "Newton did not converge from " + std::to_string(done) + " to " + std::to_string(to) +
             " of " + what + " after " + std::to_string(options.max_cutbacks) +
             " halvings of the increment (residual " + std::to_string(sol.residual_n) + " N)";
    ++sol.cutbacks, size *= 0.5;
  }
  return "";
}

}  // namespace spinesim::fem::detail
