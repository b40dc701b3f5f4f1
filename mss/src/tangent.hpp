// Factorising the reduced tangent matrix with fallbacks (private to mss/): the exact Hessian
// when Cholesky succeeds, else the projected (PSD) Hessian, else the projected one plus a
// growing diagonal shift (Levenberg) — so a Newton step always has a descent direction.
#pragma once

#include "external_loads.hpp"
#include "reduced_space.hpp"
#include "sparse_cholesky.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace spinesim::mss::detail {

enum class TangentKind { exact, projected, shifted, failed };
const char* to_string(TangentKind k);

/// A <- lower(P^T (d2E + d2V_ext)(x) P) + scale * lumped (if lumped != nullptr), then factorised
/// by `chol` (analysed on first use). H: workspace for the full Hessian (pattern kept).
TangentKind factor_tangent(const MssModel& model, const ReducedSpace& space,
                           const ExternalLoads& loads, const Eigen::VectorXd& x,
                           const LumpedReduced* lumped, double lumped_scale,
                           Eigen::SparseMatrix<double>& H, Eigen::SparseMatrix<double>& A,
                           SparseCholesky& chol);

}  // namespace spinesim::mss::detail
