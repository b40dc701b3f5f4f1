// The reduced tangent matrix and its solves (private to mss/).
//
// The model's Hessian is a sparse part (MssModel::hessian) plus, with the whole-disc volume
// term, a dense rank-one part k_g u u^T (MssModel::disc_volume_rank_one); the frozen implicit
// step adds the probe contacts as low-rank terms too. In reduced coordinates the operator is
// A + W W^T (W n×r, small r); A is factorised by sparse Cholesky and the low-rank part is
// solved by Woodbury (Sherman–Morrison for r = 1) with Z = A^-1 W supplied or computed:
//   (A + W W^T)^-1 b = A^-1 b - Z (I + W^T Z)^-1 Z^T b,
// O(n r) per solve once Z is known.
//
// factor_tangent falls back from the exact Hessian to the projected (PSD) one, and then to the
// projected one plus a growing diagonal shift (Levenberg), so a Newton step always descends.
#pragma once

#include "external_loads.hpp"
#include "reduced_space.hpp"
#include "sparse_cholesky.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace spinesim::mss::detail {

/// A factorised sparse reduced matrix plus an optional rank-one term k w w^T (k >= 0).
class TangentSolver {
 public:
  SparseCholesky& cholesky() { return chol_; }
  /// After a successful factorisation: the operator becomes A + k w w^T (k = 0: A alone).
  void set_rank_one(double k, const Eigen::VectorXd& w);
  /// The operator becomes A + W W^T, Z = A^-1 W given (n×r each, r = 0: A alone).
  void set_low_rank(const Eigen::Ref<const Eigen::MatrixXd>& W,
                    const Eigen::Ref<const Eigen::MatrixXd>& Z);
  /// b <- (A + W W^T)^-1 b; allocates nothing when there is no low-rank part.
  void solve_in_place(Eigen::VectorXd& b);
  /// The current low-rank part (for reuse by the caller), n×r.
  const Eigen::MatrixXd& low_rank_W() const { return W_; }
  const Eigen::MatrixXd& low_rank_Z() const { return Z_; }

 private:
  SparseCholesky chol_;
  Eigen::MatrixXd W_, Z_;
  Eigen::LDLT<Eigen::MatrixXd> S_;  ///< I + W^T Z
  Eigen::VectorXd t_;
};

/// The reduced rank-one part of the model's Hessian at x: returns k_g and sets w = P^T u
/// (u: full workspace); 0 when the model has no whole-disc volume term.
double reduced_rank_one(const MssModel& model, const ReducedSpace& space, const Eigen::VectorXd& x,
                        Eigen::VectorXd& u, Eigen::VectorXd& w);

enum class TangentKind { exact, projected, shifted, failed };
const char* to_string(TangentKind k);

/// A <- lower(P^T (d2E + d2V_ext)(x) P) + scale * lumped (if lumped != nullptr), factorised by
/// `solver` (analysed on first use), with the model's rank-one part attached. H: workspace for
/// the full sparse Hessian (pattern kept).
TangentKind factor_tangent(const MssModel& model, const ReducedSpace& space,
                           const ExternalLoads& loads, const Eigen::VectorXd& x,
                           const LumpedReduced* lumped, double lumped_scale,
                           Eigen::SparseMatrix<double>& H, Eigen::SparseMatrix<double>& A,
                           TangentSolver& solver);

}  // namespace spinesim::mss::detail
