// Shared scenes of the haptics tests: parametric vertebrae, meshed once per build. ctest runs
// every test in its own process, and CGAL Mesh_3 without optimisation (the sanitizer build)
// takes a minute or two per vertebra, so a meshed surface is kept on disk in the test folder,
// keyed by body, resolution and this test program's own modification time (a rebuilt mesher
// relinks the program, which retires the old files). Written atomically: parallel tests either
// find a whole file or mesh it themselves.
#pragma once

#include "spinesim/haptics/scene.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

namespace spinesim::haptics::testing {

/// Triangles of the test vertebrae: enough for the vertebra's shape (about 2 mm triangles).
inline constexpr int kTestTriangles = 2500;

inline std::string cache_key() {
  struct stat st {};
  if (::stat("/proc/self/exe", &st) != 0) return "nocache";
  return std::to_string(st.st_mtime);
}

/// The parametric vertebra `name` with about `triangles` triangles.
inline const mesh::VertebraSurface& vertebra(const std::string& name,
                                             int triangles = kTestTriangles) {
  namespace fs = std::filesystem;
  static std::map<std::pair<std::string, int>, mesh::VertebraSurface> memory;
  const auto key = std::make_pair(name, triangles);
  if (auto it = memory.find(key); it != memory.end()) return it->second;
  const fs::path dir = fs::path(SPINESIM_TEST_TMP) / "vertebra-cache";
  fs::create_directories(dir);
  const fs::path file = dir / (name + "-" + std::to_string(triangles) + "-" + cache_key() + ".obj");
  const auto v = mesh::parametric_vertebra(name, SPINESIM_DATA_DIR);
  mesh::VertebraSurface s;
  if (!fs::exists(file))
    mesh::write_obj(file.string(), mesh::mesh_vertebra(v, triangles).surface,
                    "test cache of " + name);  // atomic
  // Always the file's coordinates, so that every process sees the same surface.
  s.name = name;
  s.frame = v.frame;
  s.surface = mesh::read_surface(file.string(), 1.0, mesh::UpAxis::y);
  return memory.emplace(key, std::move(s)).first->second;
}

// Outside every body, at least `r − tol` from its surface (the proxy sphere does not overlap
// it): the distance by the tree, inside/outside by the winding number (a nearest triangle's
// normal cannot tell at an edge, where the probe may lie behind one face and before the other).
inline bool clear_of_surfaces(const Scene& scene, const ScenePoses& poses, const Eigen::Vector3d& p,
                              double r, double tol) {
  const auto near = nearest_surface(scene, poses, p, r + 1, false);
  if (near.body >= 0 && near.distance_mm < r - tol) return false;
  for (int i = 0; i < scene.size(); ++i)
    if (winding_number(scene.body(i).tree, to_body(poses, i, p)) > 0.5) return false;
  return true;
}

/// Identity poses for every body.
inline ScenePoses identity_poses() { return ScenePoses{}; }

}  // namespace spinesim::haptics::testing
