// tube_surface (tube.hpp).
#include "spinesim/mesh/tube.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>
#include <string>

namespace spinesim::mesh {
namespace {

using Eigen::Vector3d;

void check_tube(const std::vector<Vector3d>& p, const std::vector<double>& w,
                const std::vector<double>& d, const TubeOptions& o) {
  if (p.size() < 2) throw std::invalid_argument("tube: give at least 2 points");
  if (w.size() != p.size() || d.size() != p.size())
    throw std::invalid_argument("tube: one width and one depth per point");
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p[i].allFinite())
      throw std::invalid_argument("tube: point " + std::to_string(i) + " is not finite");
    if (!(w[i] > 0) || !(d[i] > 0) || !std::isfinite(w[i]) || !std::isfinite(d[i]))
      throw std::invalid_argument("tube: the half-axes must be > 0 mm");
    if (i > 0 && (p[i] - p[i - 1]).norm() < 1e-6)
      throw std::invalid_argument("tube: points " + std::to_string(i - 1) + " and " +
                                  std::to_string(i) + " coincide");
  }
  if (o.sides < 3 || o.rings_per_segment < 1 || !o.width_direction.allFinite())
    throw std::invalid_argument("tube: sides >= 3 and rings_per_segment >= 1");
}

/// A point of the curve and its tangent on segment i at parameter s in [0, 1].
struct Sample {
  Vector3d x, tangent;
  double width, depth;
};

Sample sample(const std::vector<Vector3d>& p, const std::vector<double>& w,
              const std::vector<double>& d, std::size_t i, double s) {
  const std::size_t n = p.size();
  const Vector3d a = i == 0 ? Vector3d(2 * p[0] - p[1]) : p[i - 1];
  const Vector3d b = p[i], c = p[i + 1];
  const Vector3d e = i + 2 < n ? p[i + 2] : Vector3d(2 * p[n - 1] - p[n - 2]);
  // Uniform Catmull–Rom: x(s) = ½[2b + (c − a)s + (2a − 5b + 4c − e)s² + (−a + 3b − 3c + e)s³].
  const Vector3d k1 = c - a, k2 = 2 * a - 5 * b + 4 * c - e, k3 = -a + 3 * b - 3 * c + e;
  Sample out;
  out.x = 0.5 * (2 * b + s * (k1 + s * (k2 + s * k3)));
  out.tangent = 0.5 * (k1 + s * (2 * k2 + 3 * s * k3));
  out.width = (1 - s) * w[i] + s * w[i + 1];
  out.depth = (1 - s) * d[i] + s * d[i + 1];
  return out;
}

/// Any unit vector normal to t (|t| = 1).
Vector3d any_normal(const Vector3d& t) {
  const Vector3d axis = std::abs(t.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  return (axis - axis.dot(t) * t).normalized();
}

}  // namespace

TriSurface tube_surface(const std::vector<Vector3d>& points, const std::vector<double>& width_mm,
                        const std::vector<double>& depth_mm, const TubeOptions& o) {
  check_tube(points, width_mm, depth_mm, o);
  std::vector<Sample> rings;
  for (std::size_t i = 0; i + 1 < points.size(); ++i)
    for (int k = 0; k < o.rings_per_segment; ++k)
      rings.push_back(sample(points, width_mm, depth_mm, i, double(k) / o.rings_per_segment));
  rings.push_back(sample(points, width_mm, depth_mm, points.size() - 2, 1.0));
  for (const Sample& r : rings)
    if (!(r.tangent.norm() > 1e-9))
      throw std::invalid_argument("tube: the curve through the points stops (a cusp)");

  const int m = o.sides, nr = int(rings.size());
  TriSurface s;
  s.V.resize(Eigen::Index(nr) * m + 2, 3);
  s.F.resize(2 * Eigen::Index(nr - 1) * m + 2 * Eigen::Index(m), 3);
  Vector3d t = rings[0].tangent.normalized();
  const Vector3d wd = o.width_direction - o.width_direction.dot(t) * t;
  Vector3d n = wd.norm() > 1e-9 * (1 + o.width_direction.norm()) ? wd.normalized() : any_normal(t);
  for (int k = 0; k < nr; ++k) {
    const Vector3d tk = rings[std::size_t(k)].tangent.normalized();
    // Parallel transport: turn the normal by the rotation that takes the last tangent to this one.
    n = (Eigen::Quaterniond::FromTwoVectors(t, tk) * n).normalized();
    n = (n - n.dot(tk) * tk).normalized();
    t = tk;
    const Vector3d b = t.cross(n);
    for (int j = 0; j < m; ++j) {
      const double a = 2 * M_PI * j / m;
      s.V.row(Eigen::Index(k) * m + j) = rings[std::size_t(k)].x +
                                         rings[std::size_t(k)].width * std::cos(a) * n +
                                         rings[std::size_t(k)].depth * std::sin(a) * b;
    }
  }
  const int start = nr * m, end = start + 1;
  s.V.row(start) = rings.front().x;
  s.V.row(end) = rings.back().x;
  Eigen::Index f = 0;
  auto at = [m](int ring, int j) { return ring * m + (j % m); };
  // With (n, b = t × n, t) right-handed, (ring k, j) → (k, j+1) → (k+1, j) faces outward.
  for (int k = 0; k + 1 < nr; ++k)
    for (int j = 0; j < m; ++j) {
      s.F.row(f++) << at(k, j), at(k, j + 1), at(k + 1, j);
      s.F.row(f++) << at(k, j + 1), at(k + 1, j + 1), at(k + 1, j);
    }
  for (int j = 0; j < m; ++j) {
    s.F.row(f++) << start, at(0, j + 1), at(0, j);          // faces −t
    s.F.row(f++) << end, at(nr - 1, j), at(nr - 1, j + 1);  // faces +t
  }
  return s;
}

}  // namespace spinesim::mesh
