// Signed distance to an oriented triangle surface (a chair's backrest from a CAD file): the
// closest point by a CGAL AABB tree, the sign from the closest face's normal (positive on the
// side the normals point to). Units are the file's (mm in spinesim).
#pragma once

#include <Eigen/Core>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace spinesim::mesh {

class SurfaceDistance {
 public:
  /// Triangles (vertex indices) over `points`; degenerate triangles are dropped. Throws
  /// std::invalid_argument when nothing is left or an index or point is bad.
  SurfaceDistance(const std::vector<Eigen::Vector3d>& points,
                  const std::vector<std::array<std::size_t, 3>>& triangles);
  /// Distance to the surface, signed by the closest face's normal, and its gradient (the unit
  /// vector from the closest point, or that face's normal on the surface).
  double signed_distance(const Eigen::Vector3d& x, Eigen::Vector3d& gradient) const;
  /// Area-weighted mean of the faces' unit normals (which way the surface faces).
  Eigen::Vector3d mean_normal() const;
  std::size_t triangles() const;
  /// Bounding box corners.
  Eigen::Vector3d lower() const;
  Eigen::Vector3d upper() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

/// Reads an STL (ASCII or binary), OBJ, OFF or PLY surface in mm with io.hpp's read_surface (the
/// file's own axes; polygons split into triangle fans). Throws std::invalid_argument (one line
/// naming the file) for a missing, unreadable, empty or non-finite file, or one without a
/// triangle with an area.
SurfaceDistance read_surface_distance(const std::string& path);

}  // namespace spinesim::mesh
