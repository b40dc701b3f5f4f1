// Stable-time-step predictions of the explicit integrators (stability.hpp, solver.hpp).
#include "stability.hpp"
#include "spinesim/mss/simulator.hpp"

#include "reduced_space.hpp"
#include "spectrum.hpp"
#include "tangent.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace spinesim::mss::detail {

double predicted_stable_dt(const MssModel& model, const Eigen::SparseMatrix<double>& H_rest,
                           Integrator integrator) {
  if (integrator == Integrator::implicit_euler) return std::numeric_limits<double>::infinity();
  // Free nodes with both endplates fixed, at rest: K_ff and the lumped masses.
  const ReducedSpace fixed(model, H_rest, PlateMode::pose, Eigen::Vector3d::Zero());
  const Eigen::Index n = fixed.size();
  if (n == 0) return std::numeric_limits<double>::infinity();
  Eigen::SparseMatrix<double> K = fixed.pattern();
  fixed.reduce_matrix(H_rest, K);
  Eigen::VectorXd u, wk;  // rank-one part k_g wk wk^T of K_ff (whole-disc volume term)
  const double kg = detail::reduced_rank_one(model, fixed, model.rest_positions_mm(), u, wk);
  const auto apply_K = [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
    out.noalias() = K.selfadjointView<Eigen::Lower>() * v;
    if (kg > 0) out.noalias() += (kg * wk.dot(v)) * wk;
  };
  const Eigen::VectorXd m = fixed.lumped(model.node_masses_t()).diagonal;
  const double kd = model.damping_n_s_per_mm();
  // Every eigenpair (l, z) of a step's amplification (mu = 1 + l dt for explicit Euler) makes
  // the scalar Rayleigh quotients m_z = z*Mz, c_z = K_d |z|^2, k_z = z*Kz satisfy a quadratic
  // in mu, and the Jury conditions on that quadratic give sufficient matrix conditions:
  //   explicit    dt k_z < c_z (underdamped modes) and dt^2 k_z - 2 dt c_z + 4 m_z > 0
  //               (overdamped modes: dt < 2 / |fastest decay rate|)
  //               <= dt < min(K_d / lambda_max(K_ff), 2 m_min / K_d); the second term is the
  //               limit of a light, overdamped node (K_d / m >> omega) and binds on CGAL discs
  //               with sliver-sized rim nodes. K_d = 0: unstable at any dt, 0 is returned;
  //   symplectic  dt^2 k_z + 2 dt c_z < 4 m_z
  //               <= lambda_max(dt^2 M^-1/2 K M^-1/2 + 2 dt K_d M^-1) < 4, solved for dt by
  //               Newton on that convex increasing function of dt (2/omega_max undamped).
  // Damping lowers the symplectic limit where it is strong: on the lightest nodes (slivers at
  // the rim), K_d/m is comparable to omega_max.
  if (integrator == Integrator::explicit_euler) {
    if (kd <= 0) return 0.0;
    const detail::TopEigenpair top = detail::largest_eigenpair(apply_K, n);
    return std::min(kd / top.value, 2.0 * m.minCoeff() / kd);
  }
  const Eigen::VectorXd s = m.cwiseSqrt().cwiseInverse();  // M^-1/2
  const Eigen::VectorXd minv = m.cwiseInverse();
  Eigen::VectorXd w(n);
  const auto top_of = [&](double dt) {
    return detail::largest_eigenpair(
        [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
          w = s.cwiseProduct(v);
          apply_K(w, out);
          out = (dt * dt) * s.cwiseProduct(out) + (2.0 * dt * kd) * minv.cwiseProduct(v);
        },
        n);
  };
  // Undamped start 2/omega_max lies at or right of the root; Newton from the right converges
  // monotonically for a convex increasing function.
  const detail::TopEigenpair undamped = detail::largest_eigenpair(
      [&](const Eigen::VectorXd& v, Eigen::VectorXd& out) {
        w = s.cwiseProduct(v);
        apply_K(w, out);
        out.array() *= s.array();
      },
      n);
  double dt = 2.0 / std::sqrt(undamped.value);
  if (kd <= 0) return dt;
  for (int it = 0; it < 50; ++it) {
    const detail::TopEigenpair t = top_of(dt);
    const Eigen::VectorXd& z = t.vector;
    // d lambda / d dt = z^T (2 dt S + 2 K_d M^-1) z, S = M^-1/2 K M^-1/2.
    w = s.cwiseProduct(z);
    Eigen::VectorXd Kw(n);
    apply_K(w, Kw);
    const double zSz = w.dot(Kw);
    const double zDz = z.dot(minv.cwiseProduct(z));
    const double slope = 2.0 * dt * zSz + 2.0 * kd * zDz;
    const double step = (t.value - 4.0) / slope;
    dt -= step;
    if (std::abs(step) <= 1e-6 * dt) break;
  }
  return dt;
}

}  // namespace spinesim::mss::detail
