// Natural modes of the spine about an equilibrium (dynamics.hpp).
#include "spinesim/spine/dynamics.hpp"

#include "spinesim/spine/kinematics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::spine {

namespace {

/// kg·mm² times rad/s² is 1e-3 N·mm: the mass matrix in the equations of motion, whose other
/// terms are in N·mm.
constexpr double kInertiaNmm = 1e-3;

double point_mass_kg(const SpineModel& m, const PointLoad& w) {
  return w.force_n.norm() / (m.gravity_mm_s2 / 1000.0);
}

/// ∂x_i/∂θ of every weight's point (3 rows a weight), central differences of the poses.
Eigen::MatrixXd point_jacobian(const SpineModel& m, const Eigen::VectorXd& theta) {
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
  return J;
}

}  // namespace

Eigen::MatrixXd mass_matrix(const SpineModel& m, const Eigen::VectorXd& theta) {
  if (m.weights.empty())
    throw std::invalid_argument("mass_matrix: the model has no weights (gravity off): no masses");
  const Eigen::MatrixXd J = point_jacobian(m, theta);
  Eigen::VectorXd mass(J.rows());
  for (std::size_t i = 0; i < m.weights.size(); ++i)
    mass.segment<3>(3 * Eigen::Index(i)).setConstant(point_mass_kg(m, m.weights[i]));
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
  const Eigen::MatrixXd Kf = K(free, free), Mf = M(free, free);
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
    out.shape(free, i) = phi / std::sqrt(std::max(mu, 1e-300));
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

std::vector<ExternalLoad> inertial_loads(const SpineModel& m, const Eigen::VectorXd& theta,
                                         const Eigen::VectorXd& acceleration) {
  const Eigen::VectorXd a = point_jacobian(m, theta) * acceleration;  // mm/s²
  std::vector<ExternalLoad> out;
  for (std::size_t i = 0; i < m.weights.size(); ++i) {
    const PointLoad& w = m.weights[i];
    if (w.body == kGround) continue;
    ExternalLoad l;
    l.vertebra = w.body;
    l.has_point = true;
    l.point_mm = w.point_mm;
    l.force_n = -point_mass_kg(m, w) * a.segment<3>(3 * Eigen::Index(i)) / 1000.0;  // kg·m/s²
    out.push_back(l);
  }
  return out;
}

namespace {

/// One Newmark average-acceleration step from `s` to time t (Newton on θ_{n+1}); false, with the
/// reason, when it does not converge.
bool newmark_step(const SpineModel& m, const TimeLoads& at, const Eigen::MatrixXd& C,
                  const std::vector<int>& free, const DynamicStep& s, double t,
                  const DynamicsOptions& o, DynamicStep& next, std::string& why) {
  const double dt = t - s.t_s;
  std::vector<ExternalLoad> loads;
  Eigen::VectorXd F, g;
  at(t, loads, F);
  const Eigen::MatrixXd M = kInertiaNmm * mass_matrix(m, s.theta);
  // The iteration matrix 4/h² M + 2/h C + K(θ) over the free coordinates; K from the step's
  // start (modified Newton), refreshed at the iterate every fourth iteration.
  Eigen::LDLT<Eigen::MatrixXd> solver;
  const auto factor = [&](const Eigen::VectorXd& at_theta) {
    const Eigen::MatrixXd J =
        (4 / (dt * dt)) * M + (2 / dt) * C + stiffness_matrix(m, loads, F, at_theta);
    solver.compute(J(free, free));
  };
  factor(s.theta);
  next = {t, s.theta + dt * s.velocity, s.velocity, s.acceleration, 0};
  double scale = 0;
  for (int it = 1;; ++it) {
    // Newmark, average acceleration: a_{n+1} from θ_{n+1}; v_{n+1} trapezoidal.
    next.acceleration = (4 / (dt * dt)) * (next.theta - s.theta - dt * s.velocity) - s.acceleration;
    next.velocity = s.velocity + 0.5 * dt * (s.acceleration + next.acceleration);
    potential(m, loads, F, next.theta, &g);
    const Eigen::VectorXd r = M * next.acceleration + C * next.velocity + g;
    const Eigen::VectorXd rf = r(free);
    if (it == 1)
      scale =
          std::max({1.0, g.cwiseAbs().maxCoeff(), (M * next.acceleration).cwiseAbs().maxCoeff()});
    next.iterations = it;
    if (rf.cwiseAbs().maxCoeff() <= o.tolerance * scale) return true;
    if (it >= o.max_iterations || !rf.allFinite()) {
      why = "no convergence at t = " + std::to_string(t) + " s (residual " +
            std::to_string(rf.cwiseAbs().maxCoeff()) + " N·mm)";
      return false;
    }
    if (it % 4 == 0) factor(next.theta);
    const Eigen::VectorXd d = solver.solve(rf);
    next.theta(free) -= d;
  }
}

}  // namespace

std::vector<DynamicStep> integrate_spine(const SpineModel& m, const TimeLoads& at,
                                         const Eigen::VectorXd& theta0, double t0, double t1,
                                         const DynamicsOptions& o) {
  const int n = dof_count(m);
  if (!(o.dt_s > 0 && o.dt_s <= 0.05) || !(o.damping_ratio >= 0 && o.damping_ratio <= 1) ||
      o.max_iterations < 1 || !(o.tolerance > 0) || !(t1 > t0) || theta0.size() != n)
    throw std::invalid_argument(
        "integrate_spine: a time step in (0, 0.05] s, a damping ratio in [0, 1], t1 > t0 and "
        "one start coordinate per joint coordinate");
  if (m.rest_posture.size())
    throw std::invalid_argument(
        "the motion of a scoliotic spine is not integrated (its muscles "
        "rest in the curve)");
  std::vector<int> free;
  for (int c = 0; c < n; ++c)
    if (!m.joints[std::size_t(c / 3)].fused) free.push_back(c);
  std::vector<ExternalLoad> loads;
  Eigen::VectorXd F;
  at(t0, loads, F);
  // Rayleigh damping proportional to the start's stiffness: ζ at the first mode.
  const Eigen::MatrixXd K0 = stiffness_matrix(m, loads, F, theta0);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  if (o.damping_ratio > 0) {
    const double f1 = natural_modes(K0, mass_matrix(m, theta0), free, 1).frequency_hz[0];
    C = (2 * o.damping_ratio / (2 * M_PI * f1)) * K0;
  }
  // At rest: M a0 = −∇Π(θ0) (zero at an equilibrium). M is singular along the coordinates that
  // turn a segment about its own point mass; the least-norm solution leaves those at rest.
  Eigen::VectorXd a0 = Eigen::VectorXd::Zero(n);
  {
    Eigen::VectorXd g0;
    potential(m, loads, F, theta0, &g0);
    const Eigen::MatrixXd M0 = kInertiaNmm * mass_matrix(m, theta0);
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(M0(free, free));
    cod.setThreshold(1e-10);
    a0(free) = -cod.solve(g0(free));
  }
  DynamicStep s{t0, theta0, Eigen::VectorXd::Zero(n), a0, 0};
  std::vector<DynamicStep> out = {s};
  while (s.t_s < t1 - 1e-12) {
    double t = std::min(t1, s.t_s + o.dt_s);
    DynamicStep next;
    std::string why;
    // A step whose Newton iteration fails (a joint striking its range-of-motion bump) is halved,
    // up to 2⁶ times; the next step tries the full one again.
    for (int halvings = 0; !newmark_step(m, at, C, free, s, t, o, next, why); ++halvings) {
      if (halvings == 6) throw SolveError("integrate_spine: " + why);
      t = s.t_s + 0.5 * (t - s.t_s);
    }
    s = next;
    out.push_back(s);
  }
  return out;
}

double ramp_overshoot_bound(double first_frequency_hz, double ramp_s) {
  if (!(first_frequency_hz > 0) || !(ramp_s > 0))
    throw std::invalid_argument("ramp_overshoot_bound: frequency and ramp must be > 0");
  // Undamped, a ramp of duration T_r then held overshoots by |sin x| / x of its step, x = π T_r f1
  // (at most 1: a sudden step doubles the static answer); its envelope is min(1, 1/x).
  return std::min(1.0, 1.0 / (first_frequency_hz * M_PI * ramp_s));
}

}  // namespace spinesim::spine
