#include "spinesim/fem/fe_space.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::fem {

namespace {

// Edge lookup without hashing: for every vertex, the (higher vertex, edge node) pairs of the
// edges it is the lower end of. A vertex has ~14 edges, so a linear scan is fast.
struct EdgeTable {
  std::vector<std::vector<std::pair<int, int>>> by_low;
  explicit EdgeTable(Eigen::Index num_vertices) : by_low(std::size_t(num_vertices)) {}

  /// Returns the node of edge (a,b), creating it with index `next` if new.
  int find_or_add(int a, int b, int next, bool& added) {
    if (a > b) std::swap(a, b);
    auto& list = by_low[std::size_t(a)];
    for (const auto& [hi, node] : list)
      if (hi == b) {
        added = false;
        return node;
      }
    list.emplace_back(b, next);
    added = true;
    return next;
  }
};

}  // namespace

FeSpace make_fe_space(const mesh::TetMesh& mesh, int order) {
  if (order != 1 && order != 2)
    throw std::invalid_argument("finite-element order must be 1 (P1) or 2 (P2), got " +
                                std::to_string(order));
  FeSpace s;
  s.order = order;
  s.num_vertices = mesh.num_vertices();
  const Eigen::Index nt = mesh.num_tets();
  if (order == 1) {
    s.X = mesh.V;
    s.elements = mesh.T;
    return s;
  }
  s.elements.resize(nt, 10);
  EdgeTable table(mesh.num_vertices());
  std::vector<std::array<int, 2>> edges;
  edges.reserve(std::size_t(7 * mesh.num_vertices()));
  const int nv = int(mesh.num_vertices());
  for (Eigen::Index t = 0; t < nt; ++t) {
    for (int k = 0; k < 4; ++k) s.elements(t, k) = mesh.T(t, k);
    for (int e = 0; e < 6; ++e) {
      const int a = mesh.T(t, kP2LocalEdges[e][0]), b = mesh.T(t, kP2LocalEdges[e][1]);
      bool added = false;
      const int node = table.find_or_add(a, b, nv + int(edges.size()), added);
      if (added) edges.push_back({std::min(a, b), std::max(a, b)});
      s.elements(t, 4 + e) = node;
    }
  }
  const Eigen::Index ne = Eigen::Index(edges.size());
  s.X.resize(nv + ne, 3);
  s.X.topRows(nv) = mesh.V;
  s.edge_vertices.resize(ne, 2);
  for (Eigen::Index e = 0; e < ne; ++e) {
    s.edge_vertices(e, 0) = edges[std::size_t(e)][0];
    s.edge_vertices(e, 1) = edges[std::size_t(e)][1];
    s.X.row(nv + e) =
        0.5 * (mesh.V.row(edges[std::size_t(e)][0]) + mesh.V.row(edges[std::size_t(e)][1]));
  }
  return s;
}

Eigen::VectorXi node_surface_labels(const FeSpace& space, const mesh::TetMesh& mesh) {
  Eigen::VectorXi label(space.num_nodes());
  label.head(space.num_vertices) = mesh.surface;
  for (Eigen::Index e = 0; e < space.edge_vertices.rows(); ++e) {
    const int a = mesh.surface(space.edge_vertices(e, 0)),
              b = mesh.surface(space.edge_vertices(e, 1));
    const bool endplate = a == b && (a == int(mesh::Surface::inferior_endplate) ||
                                     a == int(mesh::Surface::superior_endplate));
    label(space.num_vertices + e) = endplate ? a : 0;
  }
  return label;
}

}  // namespace spinesim::fem
