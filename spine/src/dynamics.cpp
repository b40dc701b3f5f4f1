// Natural modes of the spine about an equilibrium (dynamics.hpp).
#include "spinesim/spine/dynamics.hpp"

#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace spinesim::spine {

Eigen::MatrixXd mass_matrix(const SpineModel& m, const Eigen::VectorXd& theta) {
  if (m.weights.empty())
    throw std::invalid_argument("mass_matrix: the model has no weights (gravity off): no masses");
  const int n = dof_count(m);
  const double h = 1e-6;  // rad
  Eigen::MatrixXd J(3 * Eigen::Index(m.weights.size()), n);
  Eigen::VectorXd t = theta;
  for (int c = 0; c < n; ++c) {
    if (m.joints[std::size_t(c / 3)].fused) {
      J.col(c).setZero();
      continue;
    }
    t[c] = theta[c] + h;
    const std::vector<Pose> up = vertebra_poses(m, t);
    t[c] = theta[c] - h;
    const std::vector<Pose> down = vertebra_poses(m, t);
    t[c] = theta[c];
    for (std::size_t i = 0; i < m.weights.size(); ++i) {
      const PointLoad& w = m.weights[i];
      J.block<3, 1>(3 * Eigen::Index(i), c) =
          (place(up, w.body, w.point_mm) - place(down, w.body, w.point_mm)) / (2 * h);
    }
  }
  Eigen::VectorXd mass(J.rows());
  for (std::size_t i = 0; i < m.weights.size(); ++i)
    mass.segment<3>(3 * Eigen::Index(i))
        .setConstant(m.weights[i].force_n.norm() / (m.gravity_mm_s2 / 1000.0));
  return J.transpose() * mass.asDiagonal() * J;
}

Eigen::MatrixXd stiffness_matrix(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                                 const Eigen::VectorXd& muscle_force_n,
                                 const Eigen::VectorXd& theta) {
  const int n = dof_count(m);
  const double h = 1e-6;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd t = theta, gp, gm;
  for (int c = 0; c < n; ++c) {
    if (m.joints[std::size_t(c / 3)].fused) continue;
    t[c] = theta[c] + h;
    potential(m, loads, muscle_force_n, t, &gp);
    t[c] = theta[c] - h;
    potential(m, loads, muscle_force_n, t, &gm);
    t[c] = theta[c];
    K.col(c) = (gp - gm) / (2 * h);
  }
  return 0.5 * (K + K.transpose());
}

NaturalModes natural_modes(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M,
                           const std::vector<int>& free, int count) {
  const Eigen::Index f = Eigen::Index(free.size());
  if (f == 0 || count < 1) throw std::invalid_argument("natural_modes: no free coordinates");
  Eigen::MatrixXd Kf(f, f), Mf(f, f);
  for (Eigen::Index a = 0; a < f; ++a)
    for (Eigen::Index b = 0; b < f; ++b) {
      Kf(a, b) = K(free[std::size_t(a)], free[std::size_t(b)]);
      Mf(a, b) = M(free[std::size_t(a)], free[std::size_t(b)]);
    }
  // K = L Lᵀ; then L⁻¹ M L⁻ᵀ ψ = μ ψ with μ = 1/λ: the lowest frequencies are its largest μ, and a
  // singular M (a segment turning about its own point mass) only gives μ = 0 (infinite ω).
  const Eigen::LLT<Eigen::MatrixXd> llt(Kf);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument(
        "natural_modes: the stiffness is not positive definite (an unstable equilibrium)");
  const Eigen::MatrixXd Linv = llt.matrixL().solve(Eigen::MatrixXd::Identity(f, f));
  const Eigen::MatrixXd A = Linv * Mf * Linv.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (A + A.transpose()));
  if (!(es.eigenvalues().maxCoeff() > 0)) throw std::invalid_argument("natural_modes: no mass");
  const int k = int(std::min<Eigen::Index>(count, f));
  NaturalModes out;
  out.frequency_hz.resize(k);
  out.shape = Eigen::MatrixXd::Zero(K.rows(), k);
  for (int i = 0; i < k; ++i) {
    const double mu = es.eigenvalues()[f - 1 - i];  // descending μ: ascending ω
    out.frequency_hz[i] = mu > 0 ? std::sqrt(1000.0 / mu) / (2 * M_PI) : INFINITY;
    // φ = L⁻ᵀ ψ; φᵀ M φ = ψᵀ A ψ = μ: normalise to 1.
    const Eigen::VectorXd phi = Linv.transpose() * es.eigenvectors().col(f - 1 - i);
    for (Eigen::Index a = 0; a < f; ++a)
      out.shape(free[std::size_t(a)], i) = phi[a] / std::sqrt(std::max(mu, 1e-300));
  }
  return out;
}

NaturalModes spine_natural_modes(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                                 const SpineSolution& solution, int count) {
  std::vector<int> free;
  for (int c = 0; c < dof_count(m); ++c)
    if (!m.joints[std::size_t(c / 3)].fused) free.push_back(c);
  const Eigen::VectorXd& F = solution.recruitment.force_n;
  NaturalModes modes =
      natural_modes(stiffness_matrix(m, loads, F.size() ? F : Eigen::VectorXd(), solution.theta),
                    mass_matrix(m, solution.theta), free, count);
  for (const PointLoad& w : m.weights) modes.mass_kg += w.force_n.norm() / (m.gravity_mm_s2 / 1000);
  return modes;
}

double ramp_overshoot_bound(double first_frequency_hz, double ramp_s) {
  if (!(first_frequency_hz > 0) || !(ramp_s > 0))
    throw std::invalid_argument("ramp_overshoot_bound: frequency and ramp must be > 0");
  // Undamped, a ramp of duration T_r then held overshoots by |sin x| / x of its step, x = π T_r f1
  // (at most 1: a sudden step doubles the static answer); its envelope is min(1, 1/x).
  return std::min(1.0, 1.0 / (first_frequency_hz * M_PI * ramp_s));
}

}  // namespace spinesim::spine
