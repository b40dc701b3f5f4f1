// The per-spring stage of the calibration: after the region fit (calibrate.hpp), one stiffness
// multiplier mu_e per main (edge) spring, on top of the fitted region scales s — the protocol's
// "optionally finer (per-spring scales with a smoothness regulariser)".
//
// Unknowns q_e = ln mu_e, one per edge spring in the model's edge order (MssModel::edge_springs;
// thousands on a real disc), bounds ln lower <= q_e <= ln upper (default mu in [0.1, 10]),
// start q = 0 (the region fit). The region scales stay fixed. Objective:
//   J(q) = J_data(s, mu)                           displacement + w_r reaction + w_k ln^2 K6 diagonal
//                                                  (objective.hpp, same cases and weights)
//        + w_s mean_{(e,f)} (q_e - q_f)^2           smoothness: pairs of edges sharing a tetrahedron
//        + w_p mean_e q_e^2                         pull towards the region fit
// Gradient, exact and local per edge (linear_mss.hpp: dK/d mu_e = k_e(s) r_e r_e^T):
//   dJ_data/d mu_e = k_e(s) [ -sum_c (n·Δlambda_c)(n·Δz_c) + (n·ΔPhi) G6 (n·ΔPhi)^T ],
//   dJ/dq_e = mu_e dJ_data/d mu_e + smoothness and prior terms,
// with the adjoint (lambda, z, Phi, G6) of objective.hpp: one factorisation and one multi-column
// solve per evaluation, whatever the number of springs. K(s, mu) is refilled on a fixed pattern.
// No Hessian: Ipopt runs limited-memory BFGS (thousands of unknowns).
//
// The result belongs to one mesh: the multipliers are indexed by its edges (tuned_disc.hpp
// refuses a per-spring file on any other mesh). The stage never returns a J above its start: if
// Ipopt ends higher, the region fit (q = 0) is kept and `kept_start` says so.
#pragma once

#include "spinesim/calibration/calibrate.hpp"
#include "spinesim/calibration/objective.hpp"
#include "spinesim/mss/model.hpp"

#include <utility>
#include <vector>

namespace spinesim::calibration {

struct PerSpringWeights {
  double smoothness = 1e-3;  ///< w_s
  double prior = 1e-4;       ///< w_p, on mean q_e^2 (the region fit's w_p default)
};

/// Ipopt settings of the per-spring stage: lower_scale / upper_scale bound every multiplier mu_e
/// (they must bracket 1, the start); limited-memory BFGS.
IpoptSettings per_spring_ipopt_defaults();

/// Pairs (e, f), e < f, of edge springs that share a tetrahedron, each once, sorted; indices in
/// the model's edge order.
std::vector<std::pair<int, int>> neighbouring_edge_pairs(const mss::MssModel& model);

struct PerSpringEvaluation {
  double value = 0;       ///< J(q)
  double smoothness = 0;  ///< mean over neighbouring pairs of (q_e - q_f)^2
  double prior = 0;       ///< mean q_e^2
  Evaluation data;  ///< data terms (data.value = J_u + w_r J_r + w_k J_k), per-case errors, K6
  Eigen::VectorXd gradient;  ///< dJ/dq (#edges; empty unless requested)
};

class PerSpringObjective {
 public:
  /// `region`: the region-level objective (its linearised model, FEM reference, training cases,
  /// w_r and w_k); `region_log_scales`: its fitted p, held fixed; `model`: the MSS the linearised
  /// model was built from (for its edges and tetrahedra). Throws std::invalid_argument for
  /// negative or non-finite weights, a model that does not match, or scales of the wrong size.
  PerSpringObjective(Objective& region, const mss::MssModel& model,
                     Eigen::VectorXd region_log_scales,
                     PerSpringWeights weights = PerSpringWeights());

  /// J at q (#edges), and dJ/dq when `with_gradient`. Throws std::runtime_error when K(s, mu) is
  /// not positive definite.
  PerSpringEvaluation evaluate(const Eigen::VectorXd& log_multipliers, bool with_gradient);

  Eigen::Index num_unknowns() const { return Eigen::Index(k_edge_.size()); }
  const std::vector<std::pair<int, int>>& neighbour_pairs() const { return pairs_; }
  const Eigen::VectorXd& region_log_scales() const { return p_; }
  const PerSpringWeights& weights() const { return w_; }

 private:
  Objective& region_;
  Eigen::VectorXd p_, s_;   // region log scales and scales
  Eigen::VectorXd k_edge_;  // k_e(s), N/mm
  std::vector<std::pair<int, int>> pairs_;
  PerSpringWeights w_;
};

struct PerSpringResult {
  bool success = false;  ///< Ipopt solved (or solved to acceptable level)
  std::string status;    ///< Ipopt's return status
  int iterations = 0, evaluations = 0;
  double seconds = 0, evaluation_seconds = 0;
  bool kept_start = false;  ///< Ipopt ended above the start's J: the region fit (q = 0) is kept
  Eigen::VectorXd log_multipliers;  ///< q at the end
  PerSpringEvaluation start, final;
};

/// Runs Ipopt (limited-memory BFGS) from q = 0. Never throws for a failed solve (success false,
/// status why); throws std::invalid_argument for bad settings (also bounds that do not bracket
/// mu = 1) and std::runtime_error when the start cannot be evaluated.
PerSpringResult calibrate_per_spring(PerSpringObjective& objective,
                                     const IpoptSettings& settings = per_spring_ipopt_defaults(),
                                     const Progress& progress = Progress());

}  // namespace spinesim::calibration
