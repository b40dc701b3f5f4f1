#include "plate_newton.hpp"

#include "spinesim/common/rotation.hpp"
#include "spinesim/common/skew.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/cholmod_solver.hpp"

#include "newton_steps.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::fem::detail {

Eigen::Matrix3d rotated_arm_jacobian(const Eigen::Vector3d& theta, const Eigen::Vector3d& arm) {
  return -rotation_exp(theta) * skew(arm) * right_jacobian(theta);
}

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

/// The linearised problem at one state.
struct Linearised {
  double energy = 0;
  int inverted = 0;
  Eigen::VectorXd r_f;               ///< internal force at the free DOF
  Vector6 g_p = Vector6::Zero();     ///< Σ J_iᵀ f_i: the plate's generalised internal force
  Eigen::SparseMatrix<double> K_ff;  ///< lower triangle
  Eigen::MatrixXd K_fp;              ///< nf×6
  Matrix6 K_pp = Matrix6::Zero();
  double reaction = 0;  ///< |Σ f| over the held and plate nodes, for the tolerance
};

class PlateNewton {
 public:
  PlateNewton(const HyperelasticBody& body, const PlateProblem& pr, const NewtonOptions& o,
              HyperelasticSolution& sol, std::vector<std::pair<double, Vector6>>& path)
      : body_(body), pr_(pr), o_(o), sol_(sol), path_(path) {
    const Eigen::Index n = body.space().num_nodes();
    role_.assign(std::size_t(n), 0);
    for (const Eigen::Index i : pr.fixed_nodes) role_[std::size_t(i)] = 1;
    slot_.assign(std::size_t(n), -1);
    for (std::size_t k = 0; k < pr.plate_nodes.size(); ++k) {
      const Eigen::Index i = pr.plate_nodes[k];
      if (role_[std::size_t(i)] != 0)
        throw std::invalid_argument("plate problem: a node both held and on the plate");
      role_[std::size_t(i)] = 2;
      slot_[std::size_t(i)] = int(k);
      arm_.push_back(body.space().X.row(i).transpose() - pr.center);
    }
    free_index_.assign(std::size_t(3 * n), -1);
    for (Eigen::Index d = 0; d < 3 * n; ++d)
      if (role_[std::size_t(d / 3)] == 0) {
        free_index_[std::size_t(d)] = Eigen::Index(free_dofs_.size());
        free_dofs_.push_back(d);
      }
    for (int k = 0; k < 6; ++k) (pr.motion_given[std::size_t(k)] ? driven_ : loaded_).push_back(k);
    uf_ = Eigen::VectorXd::Zero(Eigen::Index(free_dofs_.size()));
  }

  /// Ramps the plate values in increments, halving failing ones; fills the solution.
  Vector6 run() {
    sol_.failure = ramp(o_, sol_, "the plate load", [this](double to) {
      if (!increment(to)) return false;
      path_.emplace_back(to, p_);
      return true;
    });
    sol_.converged = sol_.failure.empty();
    const Eigen::VectorXd u = full(uf_, p_);
    const HyperelasticBody::Evaluation ev = body_.evaluate(u, false);
    sol_.energy_mj = ev.energy;
    const Eigen::Index n = body_.space().num_nodes();
    sol_.displacement_mm.resize(n, 3);
    sol_.reaction_n = Eigen::MatrixX3d::Zero(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      sol_.displacement_mm.row(i) = u.segment<3>(3 * i).transpose();
      if (role_[std::size_t(i)] != 0)
        sol_.reaction_n.row(i) = ev.force.segment<3>(3 * i).transpose();
    }
    return p_;
  }

 private:
  const HyperelasticBody& body_;
  const PlateProblem& pr_;
  const NewtonOptions& o_;
  HyperelasticSolution& sol_;
  std::vector<std::pair<double, Vector6>>& path_;
  std::vector<int> role_, slot_;  ///< per node: 0 free, 1 held, 2 plate; plate index
  std::vector<Eigen::Vector3d> arm_;
  std::vector<Eigen::Index> free_index_, free_dofs_;
  std::vector<int> driven_, loaded_;
  Eigen::VectorXd uf_;
  Vector6 p_ = Vector6::Zero();
  CholmodSolver cholesky_;
  bool analysed_ = false;

  Eigen::VectorXd full(const Eigen::VectorXd& uf, const Vector6& p) const {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * body_.space().num_nodes());
    for (std::size_t k = 0; k < free_dofs_.size(); ++k) u(free_dofs_[k]) = uf(Eigen::Index(k));
    const Eigen::Matrix3d R_minus_I = rotation_exp_minus_identity(p.tail<3>());
    for (std::size_t k = 0; k < pr_.plate_nodes.size(); ++k)
      u.segment<3>(3 * pr_.plate_nodes[k]) = p.head<3>() + R_minus_I * arm_[k];
    return u;
  }

  /// Σ_i J_iᵀ f_i over the plate nodes for the nodal forces f (3·#nodes).
  Vector6 plate_force(const Vector6& p, const Eigen::VectorXd& f) const {
    Vector6 g = Vector6::Zero();
    for (std::size_t k = 0; k < pr_.plate_nodes.size(); ++k) {
      const Eigen::Vector3d fi = f.segment<3>(3 * pr_.plate_nodes[k]);
      g.head<3>() += fi;
      g.tail<3>() += rotated_arm_jacobian(p.tail<3>(), arm_[k]).transpose() * fi;
    }
    return g;
  }

  Eigen::Matrix<double, 3, 6> jacobian(const Vector6& p, std::size_t k) const {
    Eigen::Matrix<double, 3, 6> J;
    J << Eigen::Matrix3d::Identity(), rotated_arm_jacobian(p.tail<3>(), arm_[k]);
    return J;
  }

  Linearised linearise(const Eigen::VectorXd& uf, const Vector6& p) const;

  /// Π = E − w·p over the loaded DOF at load fraction λ.
  double potential(double energy, const Vector6& p, double lambda) const {
    double work = 0;
    for (const int k : loaded_) work += lambda * pr_.value(k) * p(k);
    return energy - work;
  }

  /// Π and the residual norm ‖(r_f, g_P − λ w)‖ at a state.
  TrialPoint trial_point(const Eigen::VectorXd& uf, const Vector6& p, double lambda) const {
    const HyperelasticBody::Evaluation ev = body_.evaluate(full(uf, p), false);
    double r2 = 0;
    for (std::size_t k = 0; k < free_dofs_.size(); ++k) r2 += std::pow(ev.force(free_dofs_[k]), 2);
    const Vector6 g = plate_force(p, ev.force);
    for (const int k : loaded_) r2 += std::pow(g(k) - lambda * pr_.value(k), 2);
    return {potential(ev.energy, p, lambda), std::sqrt(r2)};
  }

  bool factorize(const Linearised& L) {
    if (!analysed_) cholesky_.analyze(L.K_ff), analysed_ = true;
    try {
      cholesky_.factorize(L.K_ff);
    } catch (const std::runtime_error&) {
      return false;
    }
    ++sol_.factorisations;
    return true;
  }

  bool solve_step(const Linearised& L, double lambda, const Vector6& dp_driven, Eigen::VectorXd& du,
                  Vector6& dp);
  bool increment(double to);
};

Linearised PlateNewton::linearise(const Eigen::VectorXd& uf, const Vector6& p) const {
  const HyperelasticBody::Evaluation ev = body_.evaluate(full(uf, p), true);
  Linearised L;
  L.energy = ev.energy;
  L.inverted = ev.inverted;
  const auto nf = Eigen::Index(free_dofs_.size());
  L.r_f.resize(nf);
  for (Eigen::Index k = 0; k < nf; ++k) L.r_f(k) = ev.force(free_dofs_[std::size_t(k)]);
  L.g_p = plate_force(p, ev.force);
  for (Eigen::Index i = 0; i < body_.space().num_nodes(); ++i)
    if (role_[std::size_t(i)] != 0) L.reaction += ev.force.segment<3>(3 * i).squaredNorm();
  L.reaction = std::sqrt(L.reaction);
  // Blocks of the symmetric tangent (stored lower): free–free, free–plate, plate–plate.
  std::vector<Eigen::Triplet<double>> ff;
  L.K_fp = Eigen::MatrixXd::Zero(nf, 6);
  std::vector<Eigen::Matrix<double, 3, 6>> J(pr_.plate_nodes.size());
  for (std::size_t k = 0; k < J.size(); ++k) J[k] = jacobian(p, k);
  const auto add = [&](Eigen::Index r, Eigen::Index c, double v) {  // entry K(r, c)
    const Eigen::Index fr = free_index_[std::size_t(r)];
    const int pc = slot_[std::size_t(c / 3)];
    if (fr >= 0 && free_index_[std::size_t(c)] >= 0 && r >= c)
      ff.emplace_back(fr, free_index_[std::size_t(c)], v);
    if (fr >= 0 && pc >= 0) L.K_fp.row(fr) += v * J[std::size_t(pc)].row(int(c % 3));
    const int pr = slot_[std::size_t(r / 3)];
    if (pr >= 0 && pc >= 0)
      L.K_pp +=
          v * J[std::size_t(pr)].row(int(r % 3)).transpose() * J[std::size_t(pc)].row(int(c % 3));
  };
  const Eigen::SparseMatrix<double>& K = ev.tangent_lower;
  for (Eigen::Index c = 0; c < K.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, c); it; ++it) {
      add(it.row(), it.col(), it.value());
      if (it.row() != it.col()) add(it.col(), it.row(), it.value());
    }
  L.K_ff.resize(nf, nf);
  L.K_ff.setFromTriplets(ff.begin(), ff.end());
  // The plate's geometric term: ∂(Σ J_iᵀ f_i)/∂θ at fixed f.
  const double h = 1e-7;
  Eigen::Matrix3d G;
  for (int d = 0; d < 3; ++d) {
    Vector6 pp = p, pm = p;
    pp(3 + d) += h, pm(3 + d) -= h;
    G.col(d) = (plate_force(pp, ev.force) - plate_force(pm, ev.force)).tail<3>() / (2 * h);
  }
  L.K_pp.bottomRightCorner<3, 3>() += 0.5 * (G + G.transpose());
  return L;
}

/// The Newton step: the driven plate DOF move by dp_driven, the loaded ones and the free nodes
/// are solved for (Schur complement on the loaded plate DOF).
bool PlateNewton::solve_step(const Linearised& L, double lambda, const Vector6& dp_driven,
                             Eigen::VectorXd& du, Vector6& dp) {
  if (!factorize(L)) return false;
  const auto nl = Eigen::Index(loaded_.size());
  Eigen::MatrixXd K_fP(L.K_fp.rows(), nl);
  Eigen::MatrixXd K_PP(nl, nl);
  Eigen::VectorXd b_P(nl);
  const Eigen::VectorXd b_f = -L.r_f - L.K_fp * dp_driven;
  const Vector6 Kp_dd = L.K_pp * dp_driven;
  for (Eigen::Index a = 0; a < nl; ++a) {
    const int k = loaded_[std::size_t(a)];
    K_fP.col(a) = L.K_fp.col(k);
    b_P(a) = -(L.g_p(k) - lambda * pr_.value(k)) - Kp_dd(k);
    for (Eigen::Index b = 0; b < nl; ++b) K_PP(a, b) = L.K_pp(k, loaded_[std::size_t(b)]);
  }
  const Eigen::VectorXd y = cholesky_.solve(b_f);
  dp = dp_driven;
  du = y;
  if (nl == 0) return true;
  const Eigen::MatrixXd Z = cholesky_.solve(K_fP);
  const Eigen::MatrixXd S = K_PP - K_fP.transpose() * Z;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0).all()) return false;
  const Eigen::VectorXd dP = ldlt.solve(b_P - K_fP.transpose() * y);
  du = y - Z * dP;
  for (Eigen::Index a = 0; a < nl; ++a) dp(loaded_[std::size_t(a)]) = dP(a);
  return true;
}

bool PlateNewton::increment(double to) {
  // Predictor: the driven DOF to their new values, the rest along the tangent, halved until no
  // element inverts.
  Vector6 dp_driven = Vector6::Zero();
  for (const int k : driven_) dp_driven(k) = to * pr_.value(k) - p_(k);
  Eigen::VectorXd du;
  Vector6 dp;
  if (!solve_step(linearise(uf_, p_), to, dp_driven, du, dp)) return false;
  Eigen::VectorXd uf = uf_;
  Vector6 p = p_;
  bool placed = false;
  for (double alpha = 1.0; alpha >= 1e-6 && !placed; alpha *= 0.5) {
    Vector6 trial_p = p_ + alpha * dp;
    for (const int k : driven_) trial_p(k) = to * pr_.value(k);
    if (body_.evaluate(full(uf_ + alpha * du, trial_p), false).inverted == 0)
      uf = uf_ + alpha * du, p = trial_p, placed = true;
  }
  if (!placed) return false;
  // Corrector: Newton on Π with the driven DOF held.
  for (int it = 0; it < o_.max_iterations; ++it) {
    const Linearised L = linearise(uf, p);
    ++sol_.newton_iterations;
    Eigen::VectorXd r(L.r_f.size() + Eigen::Index(loaded_.size()));
    r.head(L.r_f.size()) = L.r_f;
    for (std::size_t a = 0; a < loaded_.size(); ++a)
      r(L.r_f.size() + Eigen::Index(a)) = L.g_p(loaded_[a]) - to * pr_.value(loaded_[a]);
    sol_.residual_n = r.norm();
    if (!solve_step(L, to, Vector6::Zero(), du, dp)) return false;
    double step_max = du.size() ? du.cwiseAbs().maxCoeff() : 0.0;
    step_max = std::max(step_max, dp.cwiseAbs().maxCoeff());
    const double scale =
        std::max(uf.size() ? uf.cwiseAbs().maxCoeff() : 0.0, p.cwiseAbs().maxCoeff());
    if (increment_converged(r.norm(), L.reaction, step_max, scale, o_.tolerance)) {
      uf_ = uf, p_ = p;
      return true;
    }
    double slope = L.r_f.dot(du);
    for (const int k : loaded_) slope += (L.g_p(k) - to * pr_.value(k)) * dp(k);
    const double pi0 = potential(L.energy, p, to), work = L.energy - pi0;
    const double alpha =
        backtrack({pi0, r.norm()}, slope, std::max(L.energy, std::abs(work)),
                  [&](double a) { return trial_point(uf + a * du, p + a * dp, to); });
    if (alpha == 0) return false;
    uf += alpha * du, p += alpha * dp;
  }
  return false;
}

}  // namespace

PlateNewtonResult solve_plate_problem(const HyperelasticBody& body, const PlateProblem& problem,
                                      const NewtonOptions& options) {
  if (options.load_increments < 1 || options.max_iterations < 1 || !(options.tolerance > 0))
    throw std::invalid_argument("Newton options: increments, iterations >= 1, tolerance > 0");
  if (!problem.value.allFinite()) throw std::invalid_argument("plate load: not finite");
  Timer timer;
  PlateNewtonResult out;
  PlateNewton newton(body, problem, options, out.body, out.path);
  out.plate = newton.run();
  out.body.seconds = timer.seconds();
  return out;
}

}  // namespace spinesim::fem::detail
