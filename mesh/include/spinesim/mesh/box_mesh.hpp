// Structured tetrahedral box meshes (for verification against analytic solutions: tests and
// benchmarks).
//
// box_mesh: an nx×ny×nz grid of hexahedra over [x0, x0+lx]×[0, ly]×[z0, z0+lz] (mm), each hex
// split into the 6 Kuhn tetrahedra along its main diagonal (conforming across hexes because
// every hex is split the same way), all positively oriented. Labels: surface 1 on y = 0
// (inferior endplate), 2 on y = ly (superior endplate), 3 on the other boundary faces,
// 0 inside; region 1 everywhere.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace spinesim::mesh {

inline mesh::TetMesh box_mesh(int nx, int ny, int nz, double lx, double ly, double lz,
                              const Eigen::Vector3d& origin = Eigen::Vector3d::Zero()) {
  mesh::TetMesh m;
  const auto vid = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  m.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  m.surface.setZero(m.V.rows());
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        const int v = vid(i, j, k);
        m.V.row(v) << origin.x() + lx * i / nx, origin.y() + ly * j / ny, origin.z() + lz * k / nz;
        if (j == 0)
          m.surface(v) = 1;
        else if (j == ny)
          m.surface(v) = 2;
        else if (i == 0 || i == nx || k == 0 || k == nz)
          m.surface(v) = 3;
      }
  static const std::array<std::array<int, 3>, 6> perms{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  m.T.resize(6 * nx * ny * nz, 4);
  int t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& p : perms) {
          std::array<int, 3> c{i, j, k};
          std::array<int, 4> tet;
          tet[0] = vid(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[std::size_t(p[std::size_t(s)])];
            tet[std::size_t(s + 1)] = vid(c[0], c[1], c[2]);
          }
          m.T.row(t) << tet[0], tet[1], tet[2], tet[3];
          if (mesh::tet_volume(m, t) < 0) std::swap(m.T(t, 2), m.T(t, 3));
          ++t;
        }
  m.region.setOnes(m.T.rows());
  m.source = "structured box";
  return m;
}

/// Unit cube [0,1]^3 with n cells per side.
inline mesh::TetMesh unit_cube_mesh(int n) { return box_mesh(n, n, n, 1.0, 1.0, 1.0); }

/// Indices of vertices on the boundary of the box [lo, hi] (any coordinate at a bound).
inline std::vector<int> boundary_vertices(const mesh::TetMesh& m) {
  const Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  std::vector<int> out;
  for (int v = 0; v < m.V.rows(); ++v) {
    const double tol = 1e-12 * (hi - lo).norm();
    if (((m.V.row(v) - lo).array().abs() < tol).any() ||
        ((m.V.row(v) - hi).array().abs() < tol).any())
      out.push_back(v);
  }
  return out;
}

/// Moves every interior vertex by a random offset of up to `fraction`·h per coordinate
/// (h = smallest grid spacing), so patch tests do not rely on a regular grid.
inline void perturb_interior(mesh::TetMesh& m, double h, double fraction, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-fraction * h, fraction * h);
  std::vector<char> boundary(std::size_t(m.V.rows()), 0);
  for (int v : boundary_vertices(m)) boundary[std::size_t(v)] = 1;
  for (int v = 0; v < m.V.rows(); ++v)
    if (!boundary[std::size_t(v)])
      for (int d = 0; d < 3; ++d) m.V(v, d) += uni(rng);
}

}  // namespace spinesim::mesh

namespace spinesim::mesh {

/// A box over [-lx/2, lx/2] × [0, ly] × [z0, z0+lz] that is exactly mirror-symmetric about the
/// plane x = 0 (the right half is a box_mesh, the left half its reflection with flipped
/// orientation; the two halves share the triangulated face x = 0). nx_half cells per half.
inline mesh::TetMesh mirrored_box_mesh(int nx_half, int ny, int nz, double lx, double ly, double lz,
                                       double z0) {
  const mesh::TetMesh half = box_mesh(nx_half, ny, nz, 0.5 * lx, ly, lz, Eigen::Vector3d(0, 0, z0));
  const Eigen::Index nv = half.V.rows(), nt = half.T.rows();
  // Reflected copies of every vertex not on x = 0; vertices on the plane are shared.
  std::vector<int> mirror_of(static_cast<std::size_t>(nv));
  mesh::TetMesh m;
  std::vector<Eigen::RowVector3d> extra;
  std::vector<int> extra_surface;
  int next = int(nv);
  for (Eigen::Index v = 0; v < nv; ++v) {
    if (std::abs(half.V(v, 0)) < 1e-12) {
      mirror_of[std::size_t(v)] = int(v);
    } else {
      mirror_of[std::size_t(v)] = next++;
      extra.push_back(Eigen::RowVector3d(-half.V(v, 0), half.V(v, 1), half.V(v, 2)));
      extra_surface.push_back(half.surface(v));
    }
  }
  m.V.resize(next, 3);
  m.surface.resize(next);
  m.V.topRows(nv) = half.V;
  m.surface.head(nv) = half.surface;
  for (std::size_t i = 0; i < extra.size(); ++i) {
    m.V.row(nv + Eigen::Index(i)) = extra[i];
    m.surface(nv + Eigen::Index(i)) = extra_surface[i];
  }
  // The plane x = 0 is now interior except on the outer faces.
  for (Eigen::Index v = 0; v < nv; ++v)
    if (std::abs(half.V(v, 0)) < 1e-12 && m.surface(v) == 3) {
      const bool on_z_face =
          std::abs(half.V(v, 2) - z0) < 1e-12 || std::abs(half.V(v, 2) - z0 - lz) < 1e-12;
      if (!on_z_face) m.surface(v) = 0;
    }
  m.T.resize(2 * nt, 4);
  m.T.topRows(nt) = half.T;
  for (Eigen::Index t = 0; t < nt; ++t)  // reflection flips orientation: swap two vertices
    m.T.row(nt + t) << mirror_of[std::size_t(half.T(t, 0))], mirror_of[std::size_t(half.T(t, 1))],
        mirror_of[std::size_t(half.T(t, 3))], mirror_of[std::size_t(half.T(t, 2))];
  m.region.setOnes(2 * nt);
  m.source = "mirror-symmetric structured box";
  return m;
}

}  // namespace spinesim::mesh
