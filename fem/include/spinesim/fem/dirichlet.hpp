// Generic Dirichlet solve: K u = f with u prescribed on a set of DOFs.
//   K_ff u_f = f_f − K_fd u_d,  u_d = fixed values;  returns the full u.
// K is symmetric (both triangles stored, as from assemble_stiffness); only entries with
// row >= column are read. `ldlt` for a quasi-definite mixed system (cholmod_solver.hpp). Throws std::invalid_argument for inconsistent sizes or out-of-range
// DOFs, std::runtime_error when K_ff is not positive definite.
#pragma once

#include "spinesim/fem/cholmod_solver.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace spinesim::fem {

Eigen::VectorXd solve_dirichlet(const Eigen::SparseMatrix<double>& K, const Eigen::VectorXd& f,
                                const std::vector<Eigen::Index>& fixed_dofs,
                                const Eigen::VectorXd& fixed_values,
                                Factorization factorization = Factorization::llt);

}  // namespace spinesim::fem
