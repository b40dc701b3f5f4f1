#include "spinesim/fem/dirichlet.hpp"

#include "spinesim/fem/cholmod_solver.hpp"

#include <stdexcept>

namespace spinesim::fem {

Eigen::VectorXd solve_dirichlet(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& f,
                                const std::vector<Eigen::Index>& fixed_dofs,
                                const Eigen::VectorXd& fixed_values, Factorization factorization) {
  const Eigen::Index n = K.rows();
  if (K.cols() != n || f.size() != n)
    throw std::invalid_argument("solve_dirichlet: K must be square and match f");
  if (Eigen::Index(fixed_dofs.size()) != fixed_values.size())
    throw std::invalid_argument("solve_dirichlet: one fixed value per fixed DOF expected");
  if (!fixed_values.allFinite() || !f.allFinite())
    throw std::invalid_argument("solve_dirichlet: non-finite load or fixed value");

  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::Index> free_index(std::size_t(n), 0);
  std::vector<bool> fixed(std::size_t(n), false);
  for (std::size_t k = 0; k < fixed_dofs.size(); ++k) {
    const Eigen::Index i = fixed_dofs[k];
    if (i < 0 || i >= n) throw std::invalid_argument("solve_dirichlet: fixed DOF out of range");
    fixed[std::size_t(i)] = true;
    u(i) = fixed_values(Eigen::Index(k));
  }
  Eigen::Index nf = 0;
  for (Eigen::Index i = 0; i < n; ++i)
    free_index[std::size_t(i)] = fixed[std::size_t(i)] ? -1 : nf++;
  if (nf == 0) return u;

  Eigen::VectorXd rhs(nf);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!fixed[std::size_t(i)]) rhs(free_index[std::size_t(i)]) = f(i);
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(std::size_t(K.nonZeros() / 2 + n));
  for (Eigen::Index j = 0; j < K.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it) {
      const Eigen::Index i = it.row();
      if (i < j) continue;
      const bool fi = fixed[std::size_t(i)], fj = fixed[std::size_t(j)];
      if (!fi && !fj) {
        trip.emplace_back(free_index[std::size_t(i)], free_index[std::size_t(j)], it.value());
      } else if (!fi && fj) {
        rhs(free_index[std::size_t(i)]) -= it.value() * u(j);
      } else if (fi && !fj) {  // K(j, i) = K(i, j) by symmetry
        rhs(free_index[std::size_t(j)]) -= it.value() * u(i);
      }
    }
  Eigen::SparseMatrix<double> Kff(nf, nf);
  Kff.setFromTriplets(trip.begin(), trip.end());
  CholmodSolver solver(Ordering::automatic, factorization);
  solver.compute(Kff);
  const Eigen::VectorXd uf = solver.solve(rhs);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!fixed[std::size_t(i)]) u(i) = uf(free_index[std::size_t(i)]);
  return u;
}

}  // namespace spinesim::fem
