// A linear FEM disc held by both endplates and pressed by a rigid sphere: the static finite-element
// disc that disc palpation can step in place of the tuned mass-spring disc (the FEM the MSS is
// tuned to, at its own resolution).
//
// Small-strain linear elasticity on P1 tetrahedra with the region materials and the annulus
// fibre field of disc_fem.hpp; every node of both endplates (surface labels 1 and 2) fixed, as
// the disc is held between its vertebrae. The sphere (centre c, radius r) pushes the outer-wall
// nodes by the mass-spring probe's penalty law (mss/boundary.hpp, Probe):
//   f_i = -k_p max(0, r - |c - x_i|) n_i,   n_i = (c - x_i) / |c - x_i|,   x_i = X_i + u_i,
// the force on node i; the disc's force on the sphere is F = -sum_i f_i. Static equilibrium
// K u = f(u): the disc answers at once, it has no mass.
//
// Method. K_ff is assembled and factorised once (CHOLMOD). A wall node near the probe gets its
// compliance columns G_i = K_ff^-1 E_i (one 3-column solve, cached, least recently used dropped
// beyond `max_cache_mb`). With the candidate set S (wall nodes within r + margin of c) the
// equilibrium condenses exactly to the contact nodes: with W = G restricted to the rows of S (the
// Schur complement's inverse), u_S minimises
//   Phi(u_S) = u_S^T W^-1 u_S / 2 + sum_i k_p/2 max(0, r - |c - x_i|)^2,
// solved by Gauss-Newton (H = W^-1 + D, D = blockdiag(k_p n_i n_i^T) over the nodes in contact;
// the penalty's curvature term left out) with a backtracking line search on Phi. The full field is
// u_f = G_S f_S; a wall node outside S that the deformed disc brings within r joins S and the
// solve is repeated. The sphere's contact stiffness, -dF/dc with the disc answering, is
//   K_c = B^T (D - D H^-1 D) B = B^T (D^-1 + W)^-1 B   (B stacks 3×3 identities over S),
// the penalty springs in series with the disc's compliance: with D the exact penalty Hessian
// (its curvature term -k_p (pen / dist)(I - n n^T) makes the directions along a convex wall
// negative, about -F / r: a frictionless sphere slides off), and with D's Gauss-Newton part, the
// normal springs only (positive semi-definite; the mass-spring probe's linearisation).
// Cost per solve: O(#S^3) dense work plus u_f (3 #free × 3 #S), and 3 triangular solves per new
// node; the factorisation (~0.1–0.3 s at 20,000 tets) is made in the constructor.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>

namespace spinesim::fem {

struct ContactDiscOptions {
  double probe_radius_mm = 4;
  /// k_p per node, N/mm; 0: default_penalty() (100 times the mean edge stiffness of K_ff).
  double penalty_n_per_mm = 0;
  /// Wall nodes within r + margin of the centre are candidates; 0: r/2.
  double margin_mm = 0;
  int max_iterations = 50;
  double relative_tolerance = 1e-10;  ///< |gradient| <= tol (|W^-1 u_S| + |f_S| + 1e-12)
  /// Memory for the cached compliance columns (3 x 3 #free doubles a node: 0.3 MB a node at
  /// 20,000 tets); at least 16 nodes are kept whatever it says.
  double max_cache_mb = 128;
};

struct ContactSolveReport {
  bool ok = true;  ///< converged with finite numbers
  int iterations = 0, candidates = 0, in_contact = 0, new_nodes = 0;
};

class ContactDisc {
 public:
  /// Throws std::invalid_argument for a mesh without both endplate labels or bad options, and
  /// std::runtime_error if K_ff is not positive definite.
  ContactDisc(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
              const ContactDiscOptions& options = ContactDiscOptions());
  ~ContactDisc();
  ContactDisc(ContactDisc&&) noexcept;
  ContactDisc& operator=(ContactDisc&&) noexcept;

  /// The static equilibrium with the sphere at `center_mm` (from the last one's contact set).
  /// On failure the disc keeps its last equilibrium.
  ContactSolveReport solve(const Eigen::Vector3d& center_mm);

  /// Solves ahead the compliance columns of up to `max_nodes` uncached wall nodes within
  /// `reach_mm` of `center_mm` (nearest first, one multi-column solve), so that a touch there
  /// does not pay for them. Returns how many were solved.
  int prefetch(const Eigen::Vector3d& center_mm, double reach_mm, int max_nodes);

  const mesh::TetMesh& mesh() const;
  const Eigen::VectorXd& rest_positions_mm() const;  ///< 3 #V
  const Eigen::VectorXd& positions_mm() const;       ///< 3 #V, the last equilibrium
  Eigen::Vector3d probe_force_n() const;             ///< the disc's force on the sphere
  const Eigen::Matrix3d& probe_stiffness() const;    ///< -dF/dc, N/mm (zero out of contact)
  /// The normal springs' part of it (positive semi-definite), N/mm.
  const Eigen::Matrix3d& probe_stiffness_gauss_newton() const;
  double volume_change() const;  ///< (V - V0) / V0 of the last equilibrium
  double penalty_n_per_mm() const;
  /// 100 trace(K_ff) / (2 #edges): the mass-spring probe's default rule on the FEM stiffness.
  double default_penalty() const;
  Eigen::Index num_free_dofs() const;
  std::int64_t column_solves() const;  ///< nodes whose compliance columns were solved
  std::size_t cached_nodes() const;    ///< nodes whose columns are kept now

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace spinesim::fem
