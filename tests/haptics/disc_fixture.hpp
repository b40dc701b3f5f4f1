// The disc the palpation tests press: the structured L4-L5 disc (2,400 tets, surface nodes
// 2.8–3.7 mm apart), its most anterior mid-height wall node, and a scripted press on it.
// Shared by the mass-spring (tests/haptics) and FEM (tests/studies) palpation tests.
#pragma once

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace spinesim::test {

inline const mesh::TetMesh& structured_l4l5_disc() {
  static const mesh::TetMesh m = [] {
    mesh::StructuredDiscOptions o;
    o.sectors = 40;
    o.layers = 4;
    return mesh::mesh_structured_disc(mesh::disc_dimensions("L4-L5", SPINESIM_DATA_DIR), o);
  }();
  return m;
}

/// The most anterior mid-height surface node (local frame: +z anterior) and the outward normal.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> anterior_wall(const mesh::TetMesh& m) {
  Eigen::Index best = 0;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (std::abs(m.V(i, 1)) < 1e-9 && m.V(i, 2) > m.V(best, 2)) best = i;
  return {m.V.row(best).transpose(), Eigen::Vector3d(0, 0, 1)};
}

/// A probe of radius `r` approaching from 6 mm out over 0.2 s, pressing `depth` mm past first
/// touch over `press_s`, holding 0.2 s, withdrawing over `press_s`: its centre at 1 kHz, 1.2 s.
inline std::vector<Eigen::Vector3d> press_path(const mesh::TetMesh& m, double r, double depth,
                                               double press_s) {
  const auto [wall, n] = anterior_wall(m);
  std::vector<Eigen::Vector3d> path;
  for (int k = 0; k < 1200; ++k) {
    const double t = k * 1e-3;
    const double in = t < 0.2             ? -6.0 + 6.0 * t / 0.2
                      : t < 0.2 + press_s ? depth * (t - 0.2) / press_s
                      : t < 0.4 + press_s
                          ? depth
                          : depth * std::max(0.0, 1 - (t - 0.4 - press_s) / press_s);
    path.push_back(wall + (r - in) * n);
  }
  return path;
}

}  // namespace spinesim::test
