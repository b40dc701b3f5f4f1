// The private sparse Cholesky (mss/src/sparse_cholesky.hpp): a several-column solve gives what
// one column at a time gives, and A x = b, on every backend.
#include "sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>

#include <random>
#include <vector>

namespace spinesim::mss::detail {
namespace {

/// A 1-D Laplacian plus a diagonal and some random couplings: symmetric positive definite.
Eigen::SparseMatrix<double> spd(int n) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 4.0);
    if (i + 1 < n) t.emplace_back(i + 1, i, -1.0), t.emplace_back(i, i + 1, -1.0);
  }
  for (int k = 0; k < n; ++k) {
    const int i = pick(rng), j = pick(rng);
    if (i == j) continue;
    t.emplace_back(i, j, -0.3), t.emplace_back(j, i, -0.3);
    t.emplace_back(i, i, 0.3), t.emplace_back(j, j, 0.3);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

TEST(SparseCholesky, SeveralColumnsAtOnceEqualOneAtATime) {
  const int n = 400;
  const Eigen::SparseMatrix<double> A = spd(n);
  const Eigen::SparseMatrix<double> lower = A.triangularView<Eigen::Lower>();
  for (const CholeskyBackend b :
       {CholeskyBackend::cholmod_simplicial, CholeskyBackend::cholmod_supernodal,
        CholeskyBackend::eigen_simplicial}) {
    SparseCholesky chol(b);
    chol.analyze(lower);
    ASSERT_TRUE(chol.factorize(lower));
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 7);
    Eigen::MatrixXd X = B;
    chol.solve_in_place(X);
    for (int c = 0; c < B.cols(); ++c) {
      Eigen::VectorXd x = B.col(c);
      chol.solve_in_place(x);
      EXPECT_LT((X.col(c) - x).norm(), 1e-12 * x.norm()) << "column " << c;
      EXPECT_LT((A * X.col(c) - B.col(c)).norm(), 1e-10 * B.col(c).norm());
    }
    Eigen::MatrixXd empty(n, 0);
    chol.solve_in_place(empty);  // nothing to do
    Eigen::MatrixXd wrong(n + 1, 2);
    EXPECT_THROW(chol.solve_in_place(wrong), std::logic_error);
  }
}

}  // namespace
}  // namespace spinesim::mss::detail
