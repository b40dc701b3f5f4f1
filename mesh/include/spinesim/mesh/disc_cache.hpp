// A disk cache of meshed disc levels. CGAL meshes the 21,000-tet L4-L5 disc the haptic loop
// palpates in about 0.6 s, a third of the 2 s a haptic run may take to its first tick; the mesh
// depends only on the level's morphometry and frame, the mesh options and the program that
// meshed it, so it is kept in the vertebra cache's folder, keyed by all of them, as a VTU
// (bit-exact base64) and read back.
#pragma once

#include "spinesim/mesh/disc_level.hpp"

#include <string>

namespace spinesim::mesh {

/// The key of a level's mesh: the level, its frame in the spine, the morphometry file's content,
/// every mesh option (to 17 digits) and the running program's identity, hashed (16 hex digits).
std::string disc_cache_key(const std::string& level, const MeshOptions& options,
                           const std::string& data_dir);

/// mesh_disc_level(level, options, data_dir) (placed in the spine), read from `cache_dir` when a
/// file with the same key is there and reads whole, else meshed and written there (atomically;
/// older files of the same level and cell size are removed). An empty `cache_dir`, or one that
/// cannot be written, only meshes. `hit` (optional) tells whether the cache answered.
TetMesh cached_disc_level(const std::string& level, const MeshOptions& options,
                          const std::string& data_dir, const std::string& cache_dir,
                          bool* hit = nullptr);

}  // namespace spinesim::mesh
