#include "tangent.hpp"

#include <cmath>

namespace spinesim::mss::detail {

void TangentSolver::set_rank_one(double k, const Eigen::VectorXd& w) {
  if (k <= 0.0) {
    W_.resize(w.size(), 0);
    Z_.resize(w.size(), 0);
    return;
  }
  Eigen::VectorXd z = std::sqrt(k) * w;
  chol_.solve_in_place(z);
  set_low_rank(std::sqrt(k) * w, z);
}

void TangentSolver::set_low_rank(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                 const Eigen::Ref<const Eigen::MatrixXd>& Z) {
  W_ = W;
  Z_ = Z;
  if (W_.cols() == 0) return;
  const Eigen::MatrixXd S = Eigen::MatrixXd::Identity(W_.cols(), W_.cols()) + W_.transpose() * Z_;
  S_.compute(0.5 * (S + S.transpose()));
}

void TangentSolver::solve_in_place(Eigen::VectorXd& b) {
  if (Z_.cols() == 0) {
    chol_.solve_in_place(b);
    return;
  }
  t_.noalias() = Z_.transpose() * b;  // Z^T b = W^T A^-1 b
  chol_.solve_in_place(b);
  t_ = S_.solve(t_);
  b.noalias() -= Z_ * t_;
}

double reduced_rank_one(const MssModel& model, const ReducedSpace& space, const Eigen::VectorXd& x,
                        Eigen::VectorXd& u, Eigen::VectorXd& w) {
  if (!model.has_disc_volume_term()) return 0.0;
  const double k = model.disc_volume_rank_one(x, u);
  w.resize(space.size());
  space.reduce_vector(u, w);
  return k;
}

const char* to_string(TangentKind k) {
  switch (k) {
    case TangentKind::exact:
      return "exact";
    case TangentKind::projected:
      return "projected";
    case TangentKind::shifted:
      return "projected+shift";
    default:
      return "failed";
  }
}

TangentKind factor_tangent(const MssModel& model, const ReducedSpace& space,
                           const ExternalLoads& loads, const Eigen::VectorXd& x,
                           const LumpedReduced* lumped, double lumped_scale,
                           Eigen::SparseMatrix<double>& H, Eigen::SparseMatrix<double>& A,
                           TangentSolver& solver) {
  SparseCholesky& chol = solver.cholesky();
  if (A.nonZeros() != space.pattern().nonZeros()) A = space.pattern();
  const auto assemble = [&](HessianMode mode) {
    model.hessian(x, mode, H);
    space.reduce_matrix(H, A);
    if (!loads.empty()) loads.add_hessian(x, mode, space, A);
    if (lumped) space.add_lumped(*lumped, lumped_scale, A);
    if (!chol.analyzed()) chol.analyze(A);
  };
  TangentKind kind = TangentKind::failed;
  assemble(HessianMode::exact);
  if (chol.factorize(A)) {
    kind = TangentKind::exact;
  } else {
    assemble(HessianMode::projected);
    if (chol.factorize(A)) {
      kind = TangentKind::projected;
    } else {
      // Levenberg shift mu * mean|diag| on every reduced DOF, mu = 1e-8, 1e-6, ..., 1.
      const Eigen::SparseMatrix<double> base = A;
      const double mean_diag = std::max(1e-300, A.diagonal().cwiseAbs().mean());
      for (double mu = 1e-8; mu <= 1.0 && kind == TangentKind::failed; mu *= 100.0) {
        A = base;
        for (Eigen::Index k = 0; k < A.cols(); ++k) A.coeffRef(k, k) += mu * mean_diag;
        if (chol.factorize(A)) kind = TangentKind::shifted;
      }
    }
  }
  if (kind != TangentKind::failed) {
    Eigen::VectorXd u, w;
    solver.set_rank_one(reduced_rank_one(model, space, x, u, w), w);
  }
  return kind;
}

}  // namespace spinesim::mss::detail
