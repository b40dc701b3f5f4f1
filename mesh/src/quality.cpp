// Tet mesh quality: counts, dihedral angles, radius-edge ratio, edge lengths, volume.
#include "spinesim/mesh/quality.hpp"
#include "spinesim/common/constants.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace spinesim::mesh {
namespace {

// Circumradius of the tet (a, b, c, d): |center - a| with center from the 3x3 linear system
// 2 (p_i - a) . x = |p_i - a|^2 (x relative to a).
double circumradius(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  Eigen::Matrix3d A;
  A.row(0) = 2 * (b - a).transpose();
  A.row(1) = 2 * (c - a).transpose();
  A.row(2) = 2 * (d - a).transpose();
  const Eigen::Vector3d rhs((b - a).squaredNorm(), (c - a).squaredNorm(), (d - a).squaredNorm());
  return A.fullPivLu().solve(rhs).norm();
}

}  // namespace

std::array<double, 6> dihedral_angles_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const std::array<Eigen::Vector3d, 4> p{a, b, c, d};
  // Edge (i, j); the two faces sharing it are opposite to the other two vertices k and l.
  // The interior dihedral angle is pi minus the angle between the outward face normals.
  static constexpr int edges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                      {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  std::array<double, 6> out{};
  for (int e = 0; e < 6; ++e) {
    const Eigen::Vector3d& pi = p[edges[e][0]];
    const Eigen::Vector3d& pj = p[edges[e][1]];
    const Eigen::Vector3d& pk = p[edges[e][2]];
    const Eigen::Vector3d& pl = p[edges[e][3]];
    const Eigen::Vector3d u = (pj - pi).normalized();
    // Components of (pk - pi) and (pl - pi) perpendicular to the edge.
    Eigen::Vector3d vk = pk - pi, vl = pl - pi;
    vk -= vk.dot(u) * u;
    vl -= vl.dot(u) * u;
    const double cosang = std::clamp(vk.normalized().dot(vl.normalized()), -1.0, 1.0);
    out[std::size_t(e)] = std::acos(cosang) * kDegPerRad;
  }
  return out;
}

QualityReport quality_report(const TetMesh& m, double exact_volume_mm3) {
  QualityReport q;
  q.vertices = m.num_vertices();
  q.tets = m.num_tets();
  q.exact_volume_mm3 = exact_volume_mm3;
  for (Eigen::Index t = 0; t < m.region.size(); ++t) {
    if (m.region(t) == int(Region::annulus)) ++q.annulus_tets;
    if (m.region(t) == int(Region::nucleus)) ++q.nucleus_tets;
  }
  for (Eigen::Index v = 0; v < m.surface.size(); ++v) {
    if (m.surface(v) == int(Surface::inferior_endplate)) ++q.inferior_nodes;
    if (m.surface(v) == int(Surface::superior_endplate)) ++q.superior_nodes;
    if (m.surface(v) == int(Surface::outer_wall)) ++q.wall_nodes;
  }
  if (m.num_tets() == 0) return q;

  q.min_dihedral_deg = 180.0;
  q.max_dihedral_deg = 0.0;
  q.min_edge_mm = std::numeric_limits<double>::infinity();
  double ratio_sum = 0.0, edge_sum = 0.0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                          d = m.V.row(m.T(t, 3));
    for (double ang : dihedral_angles_deg(a, b, c, d)) {
      q.min_dihedral_deg = std::min(q.min_dihedral_deg, ang);
      q.max_dihedral_deg = std::max(q.max_dihedral_deg, ang);
    }
    const std::array<double, 6> len{(b - a).norm(), (c - a).norm(), (d - a).norm(),
                                    (c - b).norm(), (d - b).norm(), (d - c).norm()};
    const double shortest = *std::min_element(len.begin(), len.end());
    const double ratio = circumradius(a, b, c, d) / shortest;
    q.max_radius_edge_ratio = std::max(q.max_radius_edge_ratio, ratio);
    ratio_sum += ratio;
    q.volume_mm3 += tet_volume(m, t);
  }
  q.mean_radius_edge_ratio = ratio_sum / double(m.num_tets());
  // Unique edges for the edge-length statistics.
  std::vector<std::pair<int, int>> edges;
  edges.reserve(std::size_t(6 * m.num_tets()));
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        edges.emplace_back(std::min(m.T(t, i), m.T(t, j)), std::max(m.T(t, i), m.T(t, j)));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [i, j] : edges) {
    const double l = (m.V.row(i) - m.V.row(j)).norm();
    q.min_edge_mm = std::min(q.min_edge_mm, l);
    q.max_edge_mm = std::max(q.max_edge_mm, l);
    edge_sum += l;
  }
  q.mean_edge_mm = edge_sum / double(edges.size());
  return q;
}

}  // namespace spinesim::mesh
