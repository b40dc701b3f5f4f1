// libFuzzer target: the vertebra surface reader (STL ASCII/binary, OBJ, PLY, OFF through CGAL's
// polygon-soup readers plus our checks) on arbitrary bytes. The first byte picks the format (the
// reader chooses by extension), the rest is the file. Every input must be read or refused with
// std::invalid_argument; a crash, a hang, runaway memory, a leak or undefined behaviour is a
// finding. What is read must be a valid surface: finite vertices, indices in range; as a
// chair's backrest (surface_distance.hpp) it gives a finite signed distance or is refused.
#include "fuzz_input.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/surface_distance.hpp"

#include <array>
#include <vector>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".stl", ".obj", ".off", ".ply"};
  const std::string path =
      spinesim::fuzz::input_file("surface", data + 1, size - 1, kExtensions[data[0] % 4]);
  try {
    const spinesim::mesh::TriSurface s =
        spinesim::mesh::read_surface(path, 1.0, spinesim::mesh::UpAxis::y);
    if (!s.V.allFinite()) std::abort();
    if (s.F.size() > 0 && (s.F.minCoeff() < 0 || s.F.maxCoeff() >= s.V.rows())) std::abort();
    // The same surface as a chair's backrest: its signed distance must be finite wherever asked.
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index i = 0; i < s.V.rows(); ++i) points.push_back(s.V.row(i).transpose());
    std::vector<std::array<std::size_t, 3>> tris;
    for (Eigen::Index f = 0; f < s.F.rows(); ++f)
      tris.push_back({std::size_t(s.F(f, 0)), std::size_t(s.F(f, 1)), std::size_t(s.F(f, 2))});
    const spinesim::mesh::SurfaceDistance d(points, tris);
    Eigen::Vector3d g;
    if (!std::isfinite(d.signed_distance(Eigen::Vector3d(1, 2, 3), g)) || !g.allFinite())
      std::abort();
  } catch (const std::invalid_argument&) {}
  return 0;
}
