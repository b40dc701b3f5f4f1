// Sparse Cholesky (CHOLMOD supernodal LL^T) behind one small interface: analyse the pattern
// once, factorise (again when values change), solve. Only the lower triangle of the symmetric
// matrix is read. `Factorization::ldlt` factorises symmetric quasi-definite matrices
// [[A, B^T], [B, -C]] (A, C positive definite; mixed displacement–pressure systems) by CHOLMOD's
// simplicial LDL^T without pivoting: such matrices have an LDL^T factorisation for every
// symmetric ordering (Vanderbei 1995), so the fill-reducing ordering is free. Failures throw std::runtime_error with a one-line reason
// ("... matrix is not positive definite ..."), non-finite input or output included.
// CHOLMOD stays out of public headers (it is a private dependency of spinesim::fem).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>

namespace spinesim::fem {

/// Fill-reducing ordering: CHOLMOD's default choice (AMD, METIS if AMD fills badly), or one
/// method forced.
enum class Ordering { automatic, amd, metis, nesdis };

/// LL^T (symmetric positive definite) or LDL^T (symmetric quasi-definite).
enum class Factorization { llt, ldlt };

class CholmodSolver {
 public:
  explicit CholmodSolver(Ordering ordering = Ordering::automatic,
                         Factorization factorization = Factorization::llt);
  ~CholmodSolver();
  CholmodSolver(CholmodSolver&&) noexcept;
  CholmodSolver& operator=(CholmodSolver&&) noexcept;

  /// Fill-reducing ordering and symbolic factorisation of `lower` (n×n, lower triangle).
  void analyze(const Eigen::SparseMatrix<double>& lower);
  /// Numeric factorisation; the pattern must match the analysed one.
  void factorize(const Eigen::SparseMatrix<double>& lower);
  /// analyze + factorize.
  void compute(const Eigen::SparseMatrix<double>& lower) { analyze(lower), factorize(lower); }
  /// Solves A X = B for n×k right-hand sides.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const;

  Eigen::Index rows() const { return rows_; }
  /// After analyze(): nonzeros of the Cholesky factor and the factorisation flop count, as
  /// predicted by CHOLMOD's symbolic analysis (to judge orderings and BLAS throughput).
  double factor_nonzeros() const;
  double factor_flops() const;
  /// After analyze(): the ordering actually used ("amd", "metis", ...).
  const char* ordering_used() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Index rows_ = 0;
  bool factorized_ = false;
  Factorization factorization_ = Factorization::llt;
};

}  // namespace spinesim::fem
