#include "spectrum.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <random>

namespace spinesim::mss::detail {

TopEigenpair largest_eigenpair(
    const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>& apply, Eigen::Index n,
    double rel_tol, int max_iterations) {
  TopEigenpair out;
  if (n == 0) return out;
  const int m = int(std::min<Eigen::Index>(n, std::max(1, max_iterations)));
  Eigen::MatrixXd Q(n, m + 1);
  std::vector<double> alpha, beta;
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Eigen::VectorXd v(n), w(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = 1.0 + 0.5 * uni(rng);  // mostly positive, all modes
  Q.col(0) = v.normalized();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tri;
  for (int k = 0; k < m; ++k) {
    apply(Q.col(k), w);
    const double a = Q.col(k).dot(w);
    // Full reorthogonalisation (twice) against every Lanczos vector.
    for (int pass = 0; pass < 2; ++pass)
      w -= Q.leftCols(k + 1) * (Q.leftCols(k + 1).transpose() * w);
    alpha.push_back(a);
    const double b = w.norm();
    out.iterations = k + 1;
    const bool last = k + 1 == m || b <= 1e-300;
    if (last || (k + 1) % 5 == 0) {
      const int s = k + 1;
      Eigen::MatrixXd T = Eigen::MatrixXd::Zero(s, s);
      for (int i = 0; i < s; ++i) {
        T(i, i) = alpha[std::size_t(i)];
        if (i + 1 < s) T(i, i + 1) = T(i + 1, i) = beta[std::size_t(i)];
      }
      tri.compute(T);
      const double theta = tri.eigenvalues()(s - 1);
      const double resid = std::abs(b * tri.eigenvectors()(s - 1, s - 1));
      if (last || resid <= rel_tol * std::abs(theta)) {
        out.value = theta;
        out.vector = (Q.leftCols(s) * tri.eigenvectors().col(s - 1)).normalized();
        return out;
      }
    }
    beta.push_back(b);
    Q.col(k + 1) = w / b;
  }
  return out;
}

}  // namespace spinesim::mss::detail
