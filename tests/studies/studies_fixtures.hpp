// Shared inputs of the driver tests: structured disc meshes (deterministic, no CGAL; meshed once
// per level and test program) and material presets.
#pragma once

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <map>
#include <string>

namespace spinesim::test {

/// The structured disc of `level` with default options, placed in the spine.
inline const mesh::TetMesh& structured(const std::string& level) {
  static std::map<std::string, mesh::TetMesh> cache;
  auto it = cache.find(level);
  if (it == cache.end())
    it = cache.emplace(level, mesh::mesh_structured_level(level, {}, SPINESIM_DATA_DIR)).first;
  return it->second;
}

inline mesh::RegionMaterials material(const std::string& name) {
  return mesh::load_material(name, SPINESIM_DATA_DIR);
}

}  // namespace spinesim::test
