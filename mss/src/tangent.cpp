#include "tangent.hpp"

namespace spinesim::mss::detail {

const char* to_string(TangentKind k) {
  switch (k) {
    case TangentKind::exact: return "exact";
    case TangentKind::projected: return "projected";
    case TangentKind::shifted: return "projected+shift";
    default: return "failed";
  }
}

TangentKind factor_tangent(const MssModel& model, const ReducedSpace& space,
                           const ExternalLoads& loads, const Eigen::VectorXd& x,
                           const LumpedReduced* lumped, double lumped_scale,
                           Eigen::SparseMatrix<double>& H, Eigen::SparseMatrix<double>& A,
                           SparseCholesky& chol) {
  if (A.nonZeros() != space.pattern().nonZeros()) A = space.pattern();
  const auto assemble = [&](HessianMode mode) {
    model.hessian(x, mode, H);
    space.reduce_matrix(H, A);
    if (!loads.empty()) loads.add_hessian(x, mode, space, A);
    if (lumped) space.add_lumped(*lumped, lumped_scale, A);
    if (!chol.analyzed()) chol.analyze(A);
  };
  assemble(HessianMode::exact);
  if (chol.factorize(A)) return TangentKind::exact;
  assemble(HessianMode::projected);
  if (chol.factorize(A)) return TangentKind::projected;
  // Levenberg shift mu * mean|diag| on every reduced DOF, mu = 1e-8, 1e-6, ..., 1.
  const Eigen::SparseMatrix<double> base = A;
  double mean_diag = 0;
  for (Eigen::Index k = 0; k < A.cols(); ++k) mean_diag += std::abs(A.coeff(k, k));
  mean_diag = mean_diag > 0 ? mean_diag / double(A.cols()) : 1.0;
  for (double mu = 1e-8; mu <= 1.0; mu *= 100.0) {
    A = base;
    for (Eigen::Index k = 0; k < A.cols(); ++k) A.coeffRef(k, k) += mu * mean_diag;
    if (chol.factorize(A)) return TangentKind::shifted;
  }
  return TangentKind::failed;
}

}  // namespace spinesim::mss::detail
