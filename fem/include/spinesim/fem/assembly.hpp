// Global assembly of the linear-elastic stiffness on a P1/P2 node set, with the boundary
// roles of the disc problem folded in (no huge T^T K T product):
//   - free nodes: 3 unknowns each, numbered 3·free_index + (x, y, z);
//   - fixed nodes: prescribed zero displacement, dropped;
//   - plate nodes: u_i = t + theta × (x_i − c) = R_i q,  R_i = [I | −[x_i − c]×]  (3×6),
//     q = (t mm, theta rad) the 6 plate DOF.
// The reduced system  [K_ff K_fp; K_pf K_pp] [u_f; q]  is T^T K T with u = T (u_f, q):
//   K_fp = sum over free a, plate b of K_ab R_b;  K_pp = sum over plate a, b of R_a^T K_ab R_b.
// K_ff's sparsity (lower triangle, CSC) is built once; values are refilled per material.
#pragma once

#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/fibres.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/rigid_plate.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <vector>

namespace spinesim::fem {

enum class NodeRole : signed char { free = 0, fixed = 1, plate = 2 };

/// The plate map R_i (3×6) is mesh::plate_map (spinesim/mesh/rigid_plate.hpp).
using mesh::plate_map;

/// Sparsity of the free–free block (lower triangle) and per-element scatter slots.
struct FreeBlockPattern {
  std::vector<int> free_index;  ///< #nodes: index among the free nodes, −1 otherwise
  Eigen::Index num_free_nodes = 0;
  /// #T·npe·npe: for local nodes (a, b) with free indices A > B, the rank of A among the
  /// higher free neighbours of B (the 3×3 block's slot in B's columns); −1 otherwise.
  std::vector<int> slot;
  Eigen::SparseMatrix<double> lower;  ///< 3nf×3nf lower-triangular CSC pattern, values zero
};

/// How free nodes are numbered: `spatial` along a Z-order curve (memory locality for the
/// iterative solver's matrix passes), `node` in node order (free index = rank among free nodes).
enum class FreeNodeOrder { spatial, node };

FreeBlockPattern build_free_block_pattern(const FeSpace& space, const std::vector<NodeRole>& roles,
                                          FreeNodeOrder order = FreeNodeOrder::spatial);

/// Plate blocks of the reduced stiffness (see header comment).
struct PlateCoupling {
  Eigen::MatrixXd K_fp;  ///< 3nf×6 (N/mm | N/rad)
  Matrix6d K_pp;         ///< 6×6
};

/// Fills pattern.lower's values with K_ff and returns the plate blocks. `region` (#T) selects
/// each tet's material via materials.at(region). `plate_center_mm` is c. `fibres` (null or
/// empty: none) adds each tet's fibre families (fibres.hpp).
PlateCoupling assemble_constrained(const FeSpace& space, const Eigen::VectorXi& region,
                                   const mesh::RegionMaterials& materials,
                                   const std::vector<NodeRole>& roles,
                                   const Eigen::Vector3d& plate_center_mm,
                                   FreeBlockPattern& pattern,
                                   const ElementFibres* fibres = nullptr);

/// Full symmetric stiffness (both triangles), 3N×3N, N/mm, DOF 3·node + (x, y, z) in node order.
Eigen::SparseMatrix<double> assemble_stiffness(const FeSpace& space, const Eigen::VectorXi& region,
                                               const mesh::RegionMaterials& materials,
                                               const ElementFibres* fibres = nullptr);

using VectorField = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

/// Consistent load vector f_a = \int N_a b dV (3N, N) of a body force b (N/mm^3), with the
/// collapsed Gauss rule of n points per direction.
Eigen::VectorXd assemble_body_force(const FeSpace& space, const VectorField& body_force, int n = 5);

/// L² norm (mm^{5/2}) of u_h − u_exact, u_h given by its nodal values (3N, node-major), with
/// the collapsed Gauss rule of n points per direction.
double l2_error(const FeSpace& space, const Eigen::VectorXd& u_h, const VectorField& u_exact,
                int n = 6);

}  // namespace spinesim::fem
