// Surface mesh import (STL/OBJ/PLY/OFF) through CGAL's polygon-soup readers; contract in io.hpp.
//
// CGAL 5.5 quirks handled here: the readers append to the output and report an empty STL as a
// success, so emptiness is checked here; the OBJ reader's index check is off by one (an index
// equal to the vertex count passes) and negative relative indices can wrap, so every face
// index is range-checked here; OBJ `vn`/`vt` lines and the `/vt/vn` parts of face corners are
// skipped by CGAL.
#include "spinesim/mesh/io.hpp"

#include <CGAL/Simple_cartesian.h>
#include <CGAL/IO/polygon_soup_io.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;

/// File coordinates (already in mm) -> spinesim frame; the maps are documented in io.hpp.
Eigen::Vector3d to_spinesim_frame(const Eigen::Vector3d& p, UpAxis up) {
  switch (up) {
    case UpAxis::y: return {p.x(), p.y(), p.z()};
    case UpAxis::z: return {p.y(), p.z(), p.x()};
    case UpAxis::x: return {p.z(), p.x(), p.y()};
    case UpAxis::minus_y: return {p.x(), -p.y(), -p.z()};
    case UpAxis::minus_z: return {p.y(), -p.z(), -p.x()};
    case UpAxis::minus_x: return {p.z(), -p.x(), -p.y()};
  }
  return p;
}

}  // namespace

TriSurface read_surface(const std::string& path, double units_to_mm, UpAxis up) {
  auto fail = [&](const std::string& msg) {
    throw std::invalid_argument("read_surface: " + path + ": " + msg);
  };
  if (!std::isfinite(units_to_mm) || units_to_mm <= 0)
    fail("unit scale must be a positive number, got " + std::to_string(units_to_mm));

  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off")
    fail("unknown surface file extension '" + ext + "' (use .stl, .obj, .ply or .off)");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail("no such file");

  // 1. Polygon soup (no manifoldness required).
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    fail(std::string("cannot be read (") + e.what() + ")");
  }
  if (!ok) fail("cannot be read as " + ext.substr(1) + " (corrupt file, or no faces)");
  if (points.empty() || polygons.empty()) fail("contains no triangles");

  // 2. Triangles (fan for polygons), with every index checked.
  const std::size_t nv = points.size();
  std::vector<std::array<int, 3>> tris;
  tris.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    if (poly.size() < 3) fail("face #" + std::to_string(f) + " has fewer than 3 vertices");
    for (std::size_t idx : poly)
      if (idx >= nv) fail("face #" + std::to_string(f) + " has a vertex index out of range");
    for (std::size_t k = 1; k + 1 < poly.size(); ++k)
      tris.push_back({int(poly[0]), int(poly[k]), int(poly[k + 1])});
  }

  // 3. Units and frame.
  TriSurface s;
  s.V.resize(Eigen::Index(nv), 3);
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d p(points[i].x(), points[i].y(), points[i].z());
    if (!p.allFinite()) fail("vertex #" + std::to_string(i) + " has non-finite coordinates");
    s.V.row(Eigen::Index(i)) = to_spinesim_frame(units_to_mm * p, up).transpose();
  }
  s.F.resize(Eigen::Index(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) s.F(Eigen::Index(t), k) = tris[t][std::size_t(k)];
  return s;
}

}  // namespace spinesim::mesh
