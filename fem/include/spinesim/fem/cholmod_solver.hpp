// Sparse Cholesky (CHOLMOD supernodal LL^T) behind one small interface: analyse the pattern
// once, factorise (again when values change), solve. Only the lower triangle of the symmetric
// matrix is read. Failures throw std::runtime_error with a one-line reason
// ("... matrix is not positive definite ..."), non-finite input or output included.
// CHOLMOD stays out of public headers (it is a private dependency of spinesim::fem).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>

namespace spinesim::fem {

class CholmodSolver {
 public:
  CholmodSolver();
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

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Eigen::Index rows_ = 0;
  bool factorized_ = false;
};

}  // namespace spinesim::fem
