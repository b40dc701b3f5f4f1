// Two-level p-multigrid preconditioned conjugate gradients for the free–free block of a P2
// problem, several right-hand sides at once (one CG per column, sharing the matrix passes).
//
// Preconditioner (symmetric, multiplicative; Trottenberg et al., "Multigrid", 2001, ch. 2):
//   1. forward Gauss–Seidel from zero:           x = (D + L)^-1 b
//   2. coarse correction on the P1 subspace:     x += P A_c^-1 P^T (b - K x)
//   3. backward Gauss–Seidel:                    x += (D + U)^-1 (b - K x)
// P embeds P1 into P2 (vertex nodes copy, edge nodes average their two ends), so the Galerkin
// coarse matrix P^T K P is exactly the P1 stiffness on the same mesh with the same boundary
// roles; it is factorised once with CHOLMOD. Why: a direct P2 factorisation of a disc at
// ~150k DOF costs ~200 GFlop (3-D nested dissection fill), the P1 one ~1/30 of that.
#pragma once

#include "spinesim/fem/cholmod_solver.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <vector>

namespace spinesim::fem {

/// Embedding of a P1 free-node set into a P2 free-node set: fine free node i takes
/// sum_k weight[i][k] · (coarse node parent[i][k]) for parent >= 0 (at most two parents).
struct P1ToP2Embedding {
  std::vector<std::array<int, 2>> parent;
  std::vector<std::array<double, 2>> weight;
  Eigen::Index num_coarse_nodes = 0;
};

class P2MultigridCg {
 public:
  /// `fine_lower`: 3nf×3nf lower triangle of K_ff (P2); `coarse_lower`: the P1 block on the
  /// same mesh and boundary roles. Factorises the coarse block (throws like CholmodSolver).
  /// Both matrices are referenced, not copied: they must outlive this object.
  P2MultigridCg(const Eigen::SparseMatrix<double>& fine_lower,
                const Eigen::SparseMatrix<double>& coarse_lower, P1ToP2Embedding embedding);

  /// Solves K_ff X = B (3nf×k) to ||r_j|| <= rel_tol ||b_j|| per column; columns are solved in
  /// groups of 6 sharing each matrix pass (more than 6 columns: one thread per group).
  /// Throws std::runtime_error if not converged within max_iterations.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B, double rel_tol, int max_iterations);
  int last_iterations() const { return last_iterations_; }

 private:
  struct Group;  // CG on a group of columns (one thread each)

  const Eigen::SparseMatrix<double>& K_;
  const Eigen::SparseMatrix<double>& Kc_;
  P1ToP2Embedding embed_;
  CholmodSolver coarse_;
  Eigen::VectorXd inv_diag_;
  int last_iterations_ = 0;
};

}  // namespace spinesim::fem
