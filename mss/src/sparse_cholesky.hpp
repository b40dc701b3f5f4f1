// Sparse Cholesky of the reduced MSS matrices (private to mss/): analyse the fixed pattern once,
// factorise whenever the values change, solve in place without allocating. Reads the lower
// triangle only. A matrix that is not positive definite makes factorize() return false (the
// callers fall back to another Hessian); non-finite values are refused the same way.
//
// Backends: CHOLMOD simplicial or supernodal through cholmod_solve2 with reused workspace, or
// Eigen's SimplicialLLT (AMD). Default CHOLMOD supernodal (measurement in sparse_cholesky.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>

namespace spinesim::mss::detail {

enum class CholeskyBackend { cholmod_simplicial, cholmod_supernodal, eigen_simplicial };

/// The default for the MSS per-step solves (measurement in sparse_cholesky.cpp).
CholeskyBackend default_cholesky_backend();

class SparseCholesky {
 public:
  explicit SparseCholesky(CholeskyBackend backend = default_cholesky_backend());
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  /// Fill-reducing ordering and symbolic factorisation of `lower` (n×n, lower triangle).
  void analyze(const Eigen::SparseMatrix<double>& lower);
  bool analyzed() const;
  /// Numeric factorisation (pattern as analysed). False if not positive definite or not finite.
  bool factorize(const Eigen::SparseMatrix<double>& lower);
  bool factorized() const;
  /// b <- A^-1 b. Throws std::logic_error before a successful factorize().
  void solve_in_place(Eigen::VectorXd& b);
  /// B <- A^-1 B for several right-hand sides at once (one pass over the factor for all of
  /// them). Allocates.
  void solve_in_place(Eigen::MatrixXd& B);
  /// Nonzeros of the factor (after factorize), for reports.
  double factor_nonzeros() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::mss::detail
