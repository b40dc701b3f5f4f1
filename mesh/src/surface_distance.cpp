// Signed distance to a triangle surface through a CGAL AABB tree (surface_distance.hpp).
#include "spinesim/mesh/surface_distance.hpp"

#include "spinesim/mesh/io.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace spinesim::mesh {
namespace {
using K = CGAL::Simple_cartesian<double>;
using TriangleIt = std::vector<K::Triangle_3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

Eigen::Vector3d to_eigen(const K::Point_3& p) { return {p.x(), p.y(), p.z()}; }

// Beyond this, distances and cross products lose all precision (and overflow far beyond it).
constexpr double kMaxCoordinate = 1e9;
}  // namespace

struct SurfaceDistance::Impl {
  std::vector<K::Triangle_3> tris;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> areas;
  Tree tree;
  Eigen::Vector3d lo, hi;
};

SurfaceDistance::SurfaceDistance(const std::vector<Eigen::Vector3d>& points,
                                 const std::vector<std::array<std::size_t, 3>>& triangles) {
  auto impl = std::make_shared<Impl>();
  impl->lo = Eigen::Vector3d::Constant(INFINITY);
  impl->hi = -impl->lo;
  for (const auto& t : triangles) {
    for (std::size_t i : t)
      if (i >= points.size() || !(points[i].cwiseAbs().maxCoeff() <= kMaxCoordinate))
        throw std::invalid_argument(
            "surface: a triangle refers to a missing, non-finite or far point (beyond 1e9 mm)");
    const Eigen::Vector3d &a = points[t[0]], &b = points[t[1]], &c = points[t[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 1e-12)) continue;
    impl->tris.emplace_back(K::Point_3(a.x(), a.y(), a.z()), K::Point_3(b.x(), b.y(), b.z()),
                            K::Point_3(c.x(), c.y(), c.z()));
    impl->normals.push_back(n.normalized());
    impl->areas.push_back(0.5 * n.norm());
    for (const Eigen::Vector3d* p : {&a, &b, &c}) {
      impl->lo = impl->lo.cwiseMin(*p);
      impl->hi = impl->hi.cwiseMax(*p);
    }
  }
  if (impl->tris.empty()) throw std::invalid_argument("surface: no triangle with an area");
  impl->tree.insert(impl->tris.begin(), impl->tris.end());
  impl->tree.accelerate_distance_queries();
  impl_ = impl;
}

double SurfaceDistance::signed_distance(const Eigen::Vector3d& x, Eigen::Vector3d& gradient) const {
  const auto hit = impl_->tree.closest_point_and_primitive(K::Point_3(x.x(), x.y(), x.z()));
  const auto face = std::size_t(hit.second - impl_->tris.begin());
  const Eigen::Vector3d d = x - to_eigen(hit.first);
  const Eigen::Vector3d& n = impl_->normals[face];
  const double r = d.norm(), side = d.dot(n) >= 0 ? 1.0 : -1.0;
  gradient = r > 1e-9 ? Eigen::Vector3d(side * d / r) : n;
  return side * r;
}

Eigen::Vector3d SurfaceDistance::mean_normal() const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  double area = 0;
  for (std::size_t i = 0; i < impl_->normals.size(); ++i) {
    s += impl_->areas[i] * impl_->normals[i];
    area += impl_->areas[i];
  }
  return s / area;
}

std::size_t SurfaceDistance::triangles() const { return impl_->tris.size(); }
Eigen::Vector3d SurfaceDistance::lower() const { return impl_->lo; }
Eigen::Vector3d SurfaceDistance::upper() const { return impl_->hi; }

SurfaceDistance read_surface_distance(const std::string& path) {
  // The vertebra surfaces' reader (io.hpp; fuzzed): mm, the file's own axes.
  const TriSurface surface = read_surface(path, 1.0, UpAxis::y);
  std::vector<Eigen::Vector3d> points;
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i)
    points.push_back(surface.V.row(i).transpose());
  std::vector<std::array<std::size_t, 3>> tris;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f)
    tris.push_back(
        {std::size_t(surface.F(f, 0)), std::size_t(surface.F(f, 1)), std::size_t(surface.F(f, 2))});
  try {
    return SurfaceDistance(points, tris);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

}  // namespace spinesim::mesh
