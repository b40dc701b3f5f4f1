// Polygon-soup readers for OFF and PLY surfaces, used by read_surface (io_surface.cpp) in place of
// CGAL 5.5's readers: fuzzing those found undefined behaviour in CGAL's OFF scanner (a face index
// such as -7.07 converted to an unsigned integer) and a crash in its PLY reader (a `property`
// line before any `element` line indexes an empty vector), and both reserve what a header's
// counts say before reading. These readers bound every count by what the file can hold before
// anything is reserved, and refuse anything malformed with a one-line reason. Tested against
// CGAL's readers on valid files (tests/mesh/test_io_surface.cpp).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace spinesim::mesh::detail {

struct PolygonSoup {
  std::vector<Eigen::Vector3d> points;             ///< file coordinates, finite
  std::vector<std::vector<std::size_t>> polygons;  ///< 0-based indices, each < points.size()
};

/// ASCII OFF (Geomview): an optional [ST][C][N]OFF keyword line, "V F [E]", V vertex lines
/// (x y z, then anything: normals, colours, texture coordinates), F face lines ("n i1 … in",
/// then anything: a colour), nothing after them. '#' starts a comment. Binary, 4D and nD OFF are
/// refused, and so are counts that disagree with the lines the file has. Throws
/// std::invalid_argument with the reason (the caller adds the file's name).
PolygonSoup read_off_soup(const std::string& text);

/// PLY, ASCII or binary (either byte order): the `vertex` element's x, y, z (any numeric type)
/// and the `face` element's `vertex_indices` (or `vertex_index`) list (integer types); other
/// elements and properties are read past. Throws std::invalid_argument with the reason.
PolygonSoup read_ply_soup(const std::string& bytes);

}  // namespace spinesim::mesh::detail
