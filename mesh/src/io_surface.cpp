// Surface mesh import (STL/OBJ/PLY/OFF); contract in io.hpp. STL and OBJ go through CGAL's
// polygon-soup readers, OFF and PLY through our own (surface_soup.hpp: CGAL 5.5's are not safe on
// malformed files).
//
// CGAL 5.5 quirks handled here: the readers append to the output and report an empty STL as a
// success, so emptiness is checked here; the OBJ reader's index check is off by one (an index
// equal to the vertex count passes) and negative relative indices can wrap, so every face
// index is range-checked here; a NaN vertex in a binary STL would be merged away by CGAL, so
// binary STL is pre-scanned; OBJ `vn`/`vt` lines and the `/vt/vn` parts of face corners are
// skipped by CGAL.
#include "spinesim/mesh/io.hpp"

#include "spinesim/common/input_file.hpp"

#include "surface_soup.hpp"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;

/// Checks a binary STL before CGAL reads it; returns "" or the reason to refuse it.
///
/// CGAL reads a file that does not begin with the word "solid" as binary, as many facets as the
/// header counts: a count a little off (a truncated or padded file) would silently drop facets
/// and open a hole in the surface, so the file's size must be exactly what the count says.
/// CGAL also merges STL vertices through a std::map keyed on the point, and a NaN key compares
/// equivalent to anything, so a NaN vertex would silently be merged into another one: binary
/// facets are scanned for non-finite coordinates. (CGAL's ASCII parser does not accept
/// "nan"/"inf" tokens, so ASCII STL fails as unreadable instead.)
std::string check_binary_stl(const std::string& path) {
  std::ifstream is(path, std::ios::binary);
  char header[80] = {};
  std::uint32_t n = 0;
  const bool full = bool(is.read(header, 80)) && bool(is.read(reinterpret_cast<char*>(&n), 4));
  const bool ascii = std::strncmp(header, "solid", 5) == 0 &&
                     (header[5] == ' ' || header[5] == '\n' || header[5] == '\r');
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ascii || ec || size == 0) return "";  // ASCII, or empty: CGAL's reader says which
  if (!full) return "too short for a binary STL (84-byte header) and not ASCII STL";
  if (size != 84 + 50 * std::uint64_t(n))
    return "binary STL whose header counts " + std::to_string(n) + " facets (" +
           std::to_string(84 + 50 * std::uint64_t(n)) + " bytes) but the file has " +
           std::to_string(size) + " bytes: truncated, padded or not an STL file";
  char facet[50];
  for (std::uint32_t f = 0; f < n && is.read(facet, 50); ++f)
    for (int k = 3; k < 12; ++k) {  // skip the normal (floats 0-2), check the 3 vertices
      float x;
      std::memcpy(&x, facet + 4 * k, 4);
      if (!std::isfinite(x)) return "facet #" + std::to_string(f) + " has non-finite coordinates";
    }
  return "";
}

/// STL or OBJ through CGAL's reader; `fail` throws with the reason.
template <class Fail>
detail::PolygonSoup read_with_cgal(const std::string& path, const std::string& ext, Fail&& fail) {
  std::vector<Point> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    fail(std::string("cannot be read (") + e.what() + ")");
  }
  if (!ok)
    fail(std::string("cannot be read as ") + (ext == ".stl" ? "STL" : "OBJ") +
         " (corrupt file, or no faces)");
  detail::PolygonSoup soup;
  soup.points.reserve(points.size());
  for (const Point& p : points) soup.points.emplace_back(p.x(), p.y(), p.z());
  soup.polygons = std::move(polygons);
  return soup;
}

}  // namespace

Eigen::Vector3d to_spinesim_frame(const Eigen::Vector3d& p, UpAxis up) {
  switch (up) {
    case UpAxis::y:
      return {p.x(), p.y(), p.z()};
    case UpAxis::z:
      return {p.y(), p.z(), p.x()};
    case UpAxis::x:
      return {p.z(), p.x(), p.y()};
    case UpAxis::minus_y:
      return {p.x(), -p.y(), -p.z()};
    case UpAxis::minus_z:
      return {p.y(), -p.z(), -p.x()};
    case UpAxis::minus_x:
      return {p.z(), -p.x(), -p.y()};
  }
  return p;
}


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
  if (!std::filesystem::is_regular_file(path, ec))
    fail(path_kind(path).empty() ? "no such file"
                                 : "it is " + path_kind(path) + ", not a regular file");

  if (ext == ".stl") {
    const std::string bad = check_binary_stl(path);
    if (!bad.empty()) fail(bad);
  }

  // 1. Polygon soup (no manifoldness required).
  detail::PolygonSoup soup;
  if (ext == ".off" || ext == ".ply") {
    const std::string bytes = read_regular_file(path, "surface");
    try {
      soup = ext == ".off" ? detail::read_off_soup(bytes) : detail::read_ply_soup(bytes);
    } catch (const std::invalid_argument& e) {
      fail(std::string("cannot be read as ") + (ext == ".off" ? "OFF" : "PLY") + ": " + e.what());
    }
  } else {
    soup = read_with_cgal(path, ext, fail);
  }
  if (soup.points.empty() || soup.polygons.empty()) fail("contains no triangles");
  const auto& points = soup.points;
  const auto& polygons = soup.polygons;

  // 2. Triangles (fan for polygons), with every index checked.
  const std::size_t nv = points.size();
  std::vector<std::array<int, 3>> tris;
  tris.reserve(polygons.size());
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    // CGAL drops an index it cannot read (1e20) from the face: what is short is a bad index.
    if (poly.size() < 3)
      fail("face #" + std::to_string(f) + " has fewer than 3 readable vertex indices (an index " +
           "out of range or not an integer?)");
    for (std::size_t idx : poly)
      if (idx >= nv) fail("face #" + std::to_string(f) + " has a vertex index out of range");
    // A face naming one vertex twice is malformed (CGAL reads the index "1e20" as 1). Sorted,
    // so that a hostile face of a million corners costs n log n, not n^2.
    std::vector<std::size_t> sorted = poly;
    std::sort(sorted.begin(), sorted.end());
    const auto twice = std::adjacent_find(sorted.begin(), sorted.end());
    if (twice != sorted.end())
      fail("face #" + std::to_string(f) + " names vertex " + std::to_string(*twice + 1) +
           " twice (an index that is not an integer?)");
    for (std::size_t k = 1; k + 1 < poly.size(); ++k)
      tris.push_back({int(poly[0]), int(poly[k]), int(poly[k + 1])});
  }

  // 3. Units and frame.
  TriSurface s;
  s.V.resize(Eigen::Index(nv), 3);
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d& p = points[i];
    if (!p.allFinite()) fail("vertex #" + std::to_string(i) + " has non-finite coordinates");
    s.V.row(Eigen::Index(i)) = to_spinesim_frame(units_to_mm * p, up).transpose();
  }
  s.F.resize(Eigen::Index(tris.size()), 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) s.F(Eigen::Index(t), k) = tris[t][std::size_t(k)];
  return s;
}

}  // namespace spinesim::mesh
