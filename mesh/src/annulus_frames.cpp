// Lamella frames of annulus tets (annulus_frames.hpp): nearest outer-wall and interface faces
// through CGAL AABB trees.
#include "spinesim/mesh/annulus_frames.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

namespace spinesim::mesh {
namespace {

using K = CGAL::Simple_cartesian<double>;
using TriangleIt = std::vector<K::Triangle_3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, TriangleIt>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

// A set of oriented triangles with their unit normals and an AABB tree over them.
struct FaceSet {
  std::vector<K::Triangle_3> tris;
  std::vector<Eigen::Vector3d> normals;
  Tree tree;

  void add(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) return;
    tris.emplace_back(K::Point_3(a.x(), a.y(), a.z()), K::Point_3(b.x(), b.y(), b.z()),
                      K::Point_3(c.x(), c.y(), c.z()));
    normals.push_back(n.normalized());
  }
  void build() {
    if (tris.empty()) return;
    tree.insert(tris.cbegin(), tris.cend());
    tree.accelerate_distance_queries();
  }
  // Distance to the nearest face, and the unit vector from p to the closest point (the face's
  // normal, oriented towards the face, when p lies on it). The direction to the closest point
  // is the distance field's gradient: it does not jump between faces that tie.
  double nearest(const Eigen::Vector3d& p, Eigen::Vector3d& towards) const {
    const K::Point_3 q(p.x(), p.y(), p.z());
    const auto hit = tree.closest_point_and_primitive(q);
    const Eigen::Vector3d c(hit.first.x(), hit.first.y(), hit.first.z());
    const double d = (c - p).norm();
    const Eigen::Vector3d& n = normals[std::size_t(hit.second - tris.cbegin())];
    towards = d > 1e-12 ? Eigen::Vector3d((c - p) / d) : n;
    return d;
  }
};

Eigen::Vector3d row(const TetMesh& m, int v) { return m.V.row(v).transpose(); }

}  // namespace

AnnulusFrames annulus_frames(const TetMesh& m) {
  const int annulus = int(Region::annulus), nucleus = int(Region::nucleus);
  const Eigen::Index nt = m.num_tets();
  AnnulusFrames f;
  f.circumferential.setZero(nt, 3);
  f.radial.setZero(nt, 3);
  f.axial.setZero(nt, 3);
  f.depth.setConstant(nt, std::numeric_limits<double>::quiet_NaN());

  // Outer wall: boundary faces not wholly on one endplate.
  FaceSet outer, interface;
  const Eigen::MatrixX3i boundary = boundary_faces(m.T);
  const auto on_endplate = [&](int v, int label) {
    return v < m.surface.size() && m.surface(v) == label;
  };
  for (Eigen::Index i = 0; i < boundary.rows(); ++i) {
    const int a = boundary(i, 0), b = boundary(i, 1), c = boundary(i, 2);
    bool wholly_on_endplate = false;
    for (int label : {int(Surface::inferior_endplate), int(Surface::superior_endplate)})
      wholly_on_endplate |= on_endplate(a, label) && on_endplate(b, label) && on_endplate(c, label);
    if (!wholly_on_endplate) outer.add(row(m, a), row(m, b), row(m, c));
  }
  // Interface: faces of nucleus tets shared with an annulus tet, oriented out of the nucleus.
  static constexpr std::array<std::array<int, 3>, 4> kFaces{
      {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};               // outward for positive tets
  std::map<std::array<int, 3>, std::array<int, 3>> nucleus_faces;  // sorted key -> oriented face
  for (Eigen::Index t = 0; t < nt; ++t)
    if (m.region(t) == nucleus)
      for (const auto& lf : kFaces) {
        std::array<int, 3> face{m.T(t, lf[0]), m.T(t, lf[1]), m.T(t, lf[2])};
        std::array<int, 3> key = face;
        std::sort(key.begin(), key.end());
        nucleus_faces[key] = face;
      }
  bool any_annulus = false;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (m.region(t) != annulus) continue;
    any_annulus = true;
    for (const auto& lf : kFaces) {
      std::array<int, 3> key{m.T(t, lf[0]), m.T(t, lf[1]), m.T(t, lf[2])};
      std::sort(key.begin(), key.end());
      const auto it = nucleus_faces.find(key);
      if (it != nucleus_faces.end())
        interface.add(row(m, it->second[0]), row(m, it->second[1]), row(m, it->second[2]));
    }
  }
  if (!any_annulus) return f;
  if (outer.tris.empty())
    throw std::invalid_argument("annulus frames: the mesh has no outer-wall face");
  outer.build();
  interface.build();

  const Eigen::Vector3d axis = m.frame.axes.col(1).normalized();
  std::vector<double> d_outer(std::size_t(nt), 0.0);
  double max_outer = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (m.region(t) != annulus) continue;
    const Eigen::Vector3d c =
        0.25 * (row(m, m.T(t, 0)) + row(m, m.T(t, 1)) + row(m, m.T(t, 2)) + row(m, m.T(t, 3)));
    Eigen::Vector3d n_o, n_i = Eigen::Vector3d::Zero();
    const double d_o = outer.nearest(c, n_o);  // outward: towards the wall
    d_outer[std::size_t(t)] = d_o;
    max_outer = std::max(max_outer, d_o);
    double s = 1.0;
    if (!interface.tris.empty()) {
      const double d_i = interface.nearest(c, n_i);
      n_i = -n_i;  // outward: away from the nucleus
      s = d_i + d_o > 0 ? d_i / (d_i + d_o) : 1.0;
    }
    f.depth(t) = s;
    Eigen::Vector3d radial = (1 - s) * n_i + s * n_o;
    radial -= radial.dot(axis) * axis;
    if (!(radial.norm() > 1e-9)) {  // a face parallel to the endplates: use the centroid offset
      radial = c - m.frame.origin_mm;
      radial -= radial.dot(axis) * axis;
    }
    radial.normalize();
    f.radial.row(t) = radial.transpose();
    f.axial.row(t) = axis.transpose();
    f.circumferential.row(t) = axis.cross(radial).normalized().transpose();
  }
  if (interface.tris.empty())
    for (Eigen::Index t = 0; t < nt; ++t)
      if (m.region(t) == annulus)
        f.depth(t) = max_outer > 0 ? 1.0 - d_outer[std::size_t(t)] / max_outer : 1.0;
  return f;
}

}  // namespace spinesim::mesh
