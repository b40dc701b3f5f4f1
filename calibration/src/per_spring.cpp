#include "spinesim/calibration/per_spring.hpp"

#include "spinesim/common/timer.hpp"

#include "bounded_nlp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::calibration {

namespace {

bool finite_non_negative(double v) { return std::isfinite(v) && v >= 0.0; }

}  // namespace

IpoptSettings per_spring_ipopt_defaults() {
  IpoptSettings s;
  s.lower_scale = 0.1;
  s.upper_scale = 10.0;
  s.max_iterations = 1000;
  s.tolerance = 1e-6;
  s.acceptable_tolerance = 1e-4;
  return s;
}

std::vector<std::pair<int, int>> neighbouring_edge_pairs(const mss::MssModel& model) {
  std::vector<std::pair<int, int>> nodes;  // edge -> (i, j), sorted (the model's edge order)
  for (const mss::EdgeSpringInfo& e : model.edge_springs()) nodes.emplace_back(e.i, e.j);
  const auto edge_index = [&nodes](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    const auto it = std::lower_bound(nodes.begin(), nodes.end(), key);
    if (it == nodes.end() || *it != key)
      throw std::logic_error("calibration: a tetrahedron edge is not an edge spring");
    return int(it - nodes.begin());
  };
  const Eigen::MatrixX4i& T = model.mesh().T;
  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(15 * std::size_t(T.rows()));
  int tet_edges[6];
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    int k = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) tet_edges[k++] = edge_index(T(t, a), T(t, b));
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b)
        pairs.emplace_back(std::min(tet_edges[a], tet_edges[b]),
                           std::max(tet_edges[a], tet_edges[b]));
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

PerSpringObjective::PerSpringObjective(Objective& region, const mss::MssModel& model,
                                       Eigen::VectorXd p, PerSpringWeights weights)
    : region_(region), p_(std::move(p)), w_(weights) {
  if (!finite_non_negative(w_.smoothness) || !finite_non_negative(w_.prior))
    throw std::invalid_argument("calibration: per-spring weights must be finite and >= 0");
  LinearMss& lin = region_.model();
  if (p_.size() != Eigen::Index(lin.knobs().size()))
    throw std::invalid_argument("calibration: " + std::to_string(p_.size()) +
                                " region log-scales for " + std::to_string(lin.knobs().size()) +
                                " knobs");
  if (model.num_edge_springs() != lin.num_edge_springs() || model.num_dofs() != lin.num_dofs())
    throw std::invalid_argument(
        "calibration: the MSS model is not the one the linearised model was built from");
  s_ = p_.array().exp();
  k_edge_ = lin.edge_stiffness(s_);  // also checks that both main-spring knobs are tuned
  pairs_ = neighbouring_edge_pairs(model);
}

PerSpringEvaluation PerSpringObjective::evaluate(const Eigen::VectorXd& q, bool with_gradient) {
  const Eigen::Index ne = num_unknowns();
  if (q.size() != ne)
    throw std::invalid_argument("calibration: " + std::to_string(q.size()) +
                                " log-multipliers for " + std::to_string(ne) + " edge springs");
  LinearMss& lin = region_.model();
  const Eigen::VectorXd mu = q.array().exp();
  const LinearState st = lin.solve(s_, mu);
  Adjoint adj;
  PerSpringEvaluation ev;
  ev.data = region_.measure(st, with_gradient ? &adj : nullptr);
  const double n_pairs = double(std::max<std::size_t>(pairs_.size(), 1));
  for (const auto& [e, f] : pairs_) ev.smoothness += (q(e) - q(f)) * (q(e) - q(f)) / n_pairs;
  ev.prior = q.squaredNorm() / double(ne);
  ev.value = ev.data.value + w_.smoothness * ev.smoothness + w_.prior * ev.prior;
  if (!with_gradient) return ev;

  // Each spring's extension under every adjoint, response and mode column, from one product.
  const Eigen::Index nc = adj.z.cols();
  Eigen::MatrixXd columns(adj.z.rows(), 2 * nc + 6);
  columns << adj.lambda, adj.z, adj.Phi;
  const Eigen::MatrixXd ext = lin.edge_extensions(columns);  // #edges × (2 nc + 6)
  ev.gradient.resize(ne);
  for (Eigen::Index e = 0; e < ne; ++e) {
    const auto l = ext.row(e).head(nc), z = ext.row(e).segment(nc, nc);
    const Vector6d phi = ext.row(e).tail<6>().transpose();
    const double d_mu = k_edge_(e) * (-l.dot(z) + phi.dot(adj.g6 * phi));
    ev.gradient(e) = mu(e) * d_mu + w_.prior * 2.0 * q(e) / double(ne);
  }
  for (const auto& [e, f] : pairs_) {
    const double d = w_.smoothness * 2.0 * (q(e) - q(f)) / n_pairs;
    ev.gradient(e) += d;
    ev.gradient(f) -= d;
  }
  return ev;
}

PerSpringResult calibrate_per_spring(PerSpringObjective& objective, const IpoptSettings& settings,
                                     const Progress& progress) {
  validate(settings);
  if (!(settings.lower_scale < 1.0 && settings.upper_scale > 1.0))
    throw std::invalid_argument(
        "calibration: per-spring multiplier bounds must bracket 1 (the region fit), got [" +
        std::to_string(settings.lower_scale) + ", " + std::to_string(settings.upper_scale) + "]");
  const Timer t0;
  PerSpringResult out;
  const Eigen::VectorXd start = Eigen::VectorXd::Zero(objective.num_unknowns());
  out.start = objective.evaluate(start, false);  // throws if the region fit itself is unusable

  const detail::NlpFunction f = [&objective](const Eigen::VectorXd& q) {
    PerSpringEvaluation ev = objective.evaluate(q, true);
    return detail::NlpValues{ev.value, std::move(ev.gradient), Eigen::MatrixXd()};
  };
  // J is O(1e-3) and its gradient per spring far smaller: scale J to 1 at the start so that
  // Ipopt's absolute tolerances mean relative ones.
  const double scaling = out.start.value > 0 ? 1.0 / out.start.value : 1.0;
  const detail::NlpRun run = detail::run_bounded_nlp(f, start, detail::HessianKind::limited_memory,
                                                     settings, progress, scaling);
  out.status = run.status;
  out.success = run.success;
  out.iterations = run.iterations;
  out.evaluations = run.evaluations;
  out.evaluation_seconds = run.evaluation_seconds;
  out.log_multipliers = run.final_point.size() ? run.final_point : start;
  try {
    out.final = objective.evaluate(out.log_multipliers, false);
  } catch (const std::runtime_error& e) {
    out.success = false;
    out.status += std::string(" (final point unusable: ") + e.what() + ")";
    out.final = out.start;
    out.log_multipliers = start;
  }
  if (out.final.value > out.start.value) {  // never worse than the region fit
    out.kept_start = true;
    out.final = out.start;
    out.log_multipliers = start;
  }
  out.seconds = t0.seconds();
  return out;
}

}  // namespace spinesim::calibration
