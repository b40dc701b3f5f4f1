// A disk cache of meshed parametric vertebrae. Meshing a vertebra (CGAL Mesh_3) takes most of a
// second; the spine's 18 take 10–20 s before a haptic run's first tick. The surface depends only
// on the vertebra's parameters, the triangle target and the program that meshed it, so it is
// kept in a folder keyed by all three (the program by its executable's size and modification
// time: a rebuilt or updated program retires its old files) and read back bit for bit.
#pragma once

#include "spinesim/mesh/vertebra_geometry.hpp"

#include <string>

namespace spinesim::mesh {

/// The user's cache folder for spinesim: $SPINESIM_CACHE_DIR, else $XDG_CACHE_HOME/spinesim, else
/// $HOME/.cache/spinesim; empty when none of them is set.
std::string default_cache_dir();

/// The key of a vertebra's surface: its name, every parameter of its solid (to 17 digits), the
/// triangle target and the running program's identity, hashed (16 hex digits).
std::string vertebra_cache_key(const ParametricVertebra& v, int target_triangles);

/// mesh_vertebra(v, target_triangles), read from `cache_dir` when a file with the same key is
/// there and whole, else meshed and written there (atomically; older files of the same vertebra
/// and target are removed). An empty `cache_dir`, or one that cannot be written, only meshes.
/// `hit` (optional) tells whether the cache answered.
VertebraSurface cached_vertebra_surface(const ParametricVertebra& v, int target_triangles,
                                        const std::string& cache_dir, bool* hit = nullptr);

}  // namespace spinesim::mesh
