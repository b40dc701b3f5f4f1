// Shared scenes of the haptics tests: a parametric vertebra or two, meshed once per process.
#pragma once

#include "spinesim/haptics/scene.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"

#include <map>
#include <string>

namespace spinesim::haptics::testing {

/// The parametric vertebra `name` with about `triangles` triangles (cached).
inline const mesh::VertebraSurface& vertebra(const std::string& name, int triangles = 6000) {
  static std::map<std::pair<std::string, int>, mesh::VertebraSurface> cache;
  auto key = std::make_pair(name, triangles);
  auto it = cache.find(key);
  if (it == cache.end())
    it = cache
             .emplace(key, mesh::mesh_vertebra(mesh::parametric_vertebra(name, SPINESIM_DATA_DIR),
                                               triangles))
             .first;
  return it->second;
}

/// Identity poses for every body.
inline ScenePoses identity_poses() { return ScenePoses{}; }

}  // namespace spinesim::haptics::testing
