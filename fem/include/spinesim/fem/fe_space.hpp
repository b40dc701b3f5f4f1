// Finite-element node sets on a tetrahedral mesh: P1 (the vertices) and P2 (vertices plus one
// node per unique edge, at the edge midpoint — straight-sided tets).
//
// P2 node numbering: the #V mesh vertices keep their indices 0..#V-1; edge nodes follow,
// numbered #V, #V+1, ... in order of first appearance while scanning tets 0..#T-1 and their
// local edges in the order kP2LocalEdges. Element connectivity: local nodes 0-3 are the tet's
// vertices, 4-9 the midpoints of the local edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3).
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <utility>

namespace spinesim::fem {

/// Local edges of a tet, as pairs of local vertex indices; P2 local node 4 + e sits on edge e.
inline constexpr std::array<std::array<int, 2>, 6> kP2LocalEdges{
    {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}}};

struct FeSpace {
  int order = 1;                   ///< 1 (P1, 4 nodes/tet) or 2 (P2, 10 nodes/tet)
  Eigen::MatrixX3d X;              ///< #nodes×3 node positions, mm (vertices first)
  Eigen::MatrixXi elements;        ///< #T×(4 | 10) node indices per tet
  Eigen::MatrixX2i edge_vertices;  ///< #edge-nodes×2 mesh vertices of each edge node (P2)
  Eigen::Index num_vertices = 0;   ///< #V: nodes 0..#V-1 are the mesh vertices

  Eigen::Index num_nodes() const { return X.rows(); }
  int nodes_per_element() const { return int(elements.cols()); }
};

/// Builds the P1 (order 1) or P2 (order 2) node set of `mesh`. Throws std::invalid_argument
/// for any other order. The mesh is assumed valid (mesh::validate).
FeSpace make_fe_space(const mesh::TetMesh& mesh, int order);

/// Per-node surface label: vertices keep mesh.surface; a P2 edge node takes label s when both
/// ends carry s and s is an endplate label (1 or 2), otherwise 0. (Edge nodes are used only to
/// decide fixed / plate membership, so the outer-wall label is not propagated.)
Eigen::VectorXi node_surface_labels(const FeSpace& space, const mesh::TetMesh& mesh);

}  // namespace spinesim::fem
