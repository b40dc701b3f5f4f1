// Meshes, materials and boundaries shared by the MSS solver and dynamics tests.
#pragma once

#include "spinesim/mesh/box_mesh.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

#include <map>

namespace spinesim::mss::fixtures {

/// Thesis table 5.1 "real disc": E 3.22 MPa, nu 0.4557, rho 1038 kg/m^3.
inline mesh::RegionMaterials real_disc() {
  return mesh::load_material("real-disc", SPINESIM_DATA_DIR);
}

/// Parametric L4-L5 disc (47.3 x 35.5 / 46.6 x 35.0 mm, 11.3 mm high), CGAL-meshed once per
/// cell size and test process.
inline const mesh::TetMesh& l4_l5(double cell_mm) {
  static std::map<double, mesh::TetMesh> cache;
  auto it = cache.find(cell_mm);
  if (it == cache.end()) {
    mesh::MeshOptions opt;
    opt.cell_size_mm = cell_mm;
    it = cache
             .emplace(cell_mm,
                      mesh::mesh_parametric_disc({"L4-L5", 47.3, 35.5, 46.6, 35.0, 11.3}, opt))
             .first;
  }
  return it->second;
}

/// Disc-proportioned structured box, 20 x 8 x 16 mm (x, y up, z), 5 x 3 x 4 cells, centred on
/// x = z = 0; nodes at y = 0 inferior (1), y = 8 superior (2).
inline mesh::TetMesh small_box() {
  return spinesim::mesh::box_mesh(5, 3, 4, 20.0, 8.0, 16.0, Eigen::Vector3d(-10.0, 0.0, -8.0));
}

inline Vector6d vec6(double a, double b, double c, double d, double e, double f) {
  Vector6d v;
  v << a, b, c, d, e, f;
  return v;
}

/// Pose-mode boundary: inferior fixed, superior moved by q = (t mm, theta rad) about the
/// default plate centre.
inline Boundary motion_boundary(const mesh::TetMesh& m, const Vector6d& q) {
  Boundary bc;
  bc.plate_center_mm = default_plate_center(m);
  bc.superior = plate_pose(q, bc.plate_center_mm);
  return bc;
}

/// Wrench-mode boundary: inferior fixed, w = (F N, M N·mm) on the plate about its default centre.
inline Boundary wrench_boundary(const mesh::TetMesh& m, const Vector6d& w) {
  Boundary bc;
  bc.plate_center_mm = default_plate_center(m);
  bc.plate_mode = PlateMode::wrench;
  bc.wrench = w;
  return bc;
}

/// Surface-label counts.
inline int count_label(const mesh::TetMesh& m, int label) {
  return int((m.surface.array() == label).count());
}

}  // namespace spinesim::mss::fixtures
