// A fibre-reinforced disc material and a small structured disc, shared by the fibre and the
// stress-field tests.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"

namespace spinesim::fem::test {

/// Annulus E 4.2 MPa, nu 0.45 with fibres (E_f 60 -> 140 MPa, 45° -> 28° inner to outer);
/// nucleus E 1 MPa, nu 0.49.
inline mesh::RegionMaterials fibre_annulus() {
  mesh::RegionMaterials mat;
  mat.name = "test";
  mat.by_region[1] = {4.2, 0.45, 1038};
  mat.by_region[2] = {1.0, 0.49, 1038};
  mat.fallback = mat.by_region[1];
  mesh::FibreReinforcement f;
  f.modulus_inner_mpa = 60;
  f.modulus_outer_mpa = 140;
  f.angle_inner_deg = 45;
  f.angle_outer_deg = 28;
  mat.fibres[1] = f;
  return mat;
}

/// A 50 × 36 mm, 10 mm high structured disc.
inline mesh::TetMesh structured_test_disc(int sectors, int rings, int layers,
                                          const mesh::DiscFrame& placement = {}) {
  mesh::StructuredDiscOptions opt;
  opt.sectors = sectors;
  opt.rings = rings;
  opt.layers = layers;
  return mesh::mesh_structured_disc({"test", 50, 36, 50, 36, 10}, opt, placement);
}

}  // namespace spinesim::fem::test
