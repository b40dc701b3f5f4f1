// Signed distance to a triangle surface (a chair's backrest file) against brute force: the
// closest point over every triangle by projection and clamping, on a tilted square and a closed
// box; the sign and gradient from the faces' orientation; files that are not surfaces refused.
#include "spinesim/mesh/surface_distance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace sm = spinesim::mesh;
using Eigen::Vector3d;

namespace {

/// Closest point on triangle abc by brute force: the projection if inside, else the nearest
/// point of the three edges.
Vector3d closest_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                             const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a).normalized();
  const Vector3d q = p - n.dot(p - a) * n;
  auto inside = [&](const Vector3d& u, const Vector3d& v) {
    return (v - u).cross(q - u).dot(n) >= 0;
  };
  if (inside(a, b) && inside(b, c) && inside(c, a)) return q;
  Vector3d best = a;
  for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
    const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    const Vector3d e = u + t * (v - u);
    if ((p - e).norm() < (p - best).norm()) best = e;
  }
  return best;
}

/// A unit box [0,1]³ in mm × 100, outward normals.
void box(std::vector<Vector3d>& pts, std::vector<std::array<std::size_t, 3>>& tris) {
  for (int i = 0; i < 8; ++i)
    pts.emplace_back(100.0 * (i & 1), 100.0 * ((i >> 1) & 1), 100.0 * (i >> 2));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    tris.push_back({std::size_t(q[0]), std::size_t(q[1]), std::size_t(q[2])});
    tris.push_back({std::size_t(q[0]), std::size_t(q[2]), std::size_t(q[3])});
  }
}

}  // namespace

TEST(SurfaceDistance, MatchesBruteForceOnAClosedBoxWithOutsidePositive) {
  std::vector<Vector3d> pts;
  std::vector<std::array<std::size_t, 3>> tris;
  box(pts, tris);
  const sm::SurfaceDistance d(pts, tris);
  EXPECT_EQ(d.triangles(), 12u);
  EXPECT_LT(d.mean_normal().norm(), 1e-12);  // a closed surface's normals cancel
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-60, 160);
  for (int k = 0; k < 300; ++k) {
    const Vector3d p(u(rng), u(rng), u(rng));
    double best = INFINITY;
    for (const auto& t : tris)
      best = std::min(best, (p - closest_on_triangle(p, pts[t[0]], pts[t[1]], pts[t[2]])).norm());
    const bool inside = (p.array() > 0).all() && (p.array() < 100).all();
    Vector3d g;
    const double s = d.signed_distance(p, g);
    EXPECT_NEAR(std::abs(s), best, 1e-9) << p.transpose();
    EXPECT_EQ(s < 0, inside) << p.transpose();
    EXPECT_NEAR(g.norm(), 1.0, 1e-12);
    // The gradient points from the closest point out along the signed distance.
    Vector3d g2;
    const double s2 = d.signed_distance(p + 1e-3 * g, g2);
    if (std::abs(s) > 1e-2) EXPECT_NEAR(s2 - s, 1e-3, 1e-6) << p.transpose();
  }
}

TEST(SurfaceDistance, ATiltedSquareIsItsPlaneWithTheNormalsSide) {
  const double a = 20 * M_PI / 180;
  const Vector3d t(0, std::cos(a), -std::sin(a)), x(1, 0, 0), n = x.cross(t);
  std::vector<Vector3d> pts = {-200 * x, 200 * x, 200 * x + 500 * t, -200 * x + 500 * t};
  const sm::SurfaceDistance d(pts, {{0, 1, 2}, {0, 2, 3}});
  EXPECT_NEAR((d.mean_normal() - n).norm(), 0, 1e-12);
  for (double h : {-30.0, -1.0, 2.0, 40.0}) {
    Vector3d g;
    EXPECT_NEAR(d.signed_distance(10 * x + 250 * t + h * n, g), h, 1e-9);
    EXPECT_NEAR((g - n).norm(), 0, 1e-9);
  }
}

TEST(SurfaceDistance, BadTrianglesAndFilesAreRefused) {
  EXPECT_THROW(sm::SurfaceDistance({Vector3d::Zero(), Vector3d::UnitX()}, {{0, 1, 2}}),
               std::invalid_argument);
  EXPECT_THROW(sm::SurfaceDistance({Vector3d::Zero(), Vector3d::UnitX(), 2 * Vector3d::UnitX()},
                                   {{0, 1, 2}}),
               std::invalid_argument);  // no area
  EXPECT_THROW(sm::read_surface_distance("/nonexistent/back.stl"), std::invalid_argument);
  const auto dir = std::filesystem::temp_directory_path() / "spinesim_surface_distance";
  std::filesystem::create_directories(dir);
  const std::string junk = (dir / "junk.obj").string();
  std::ofstream(junk) << "hello\n";
  EXPECT_THROW(sm::read_surface_distance(junk), std::invalid_argument);
  const std::string tri = (dir / "one.obj").string();
  std::ofstream(tri) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const sm::SurfaceDistance d = sm::read_surface_distance(tri);
  EXPECT_EQ(d.triangles(), 1u);
  EXPECT_NEAR(d.mean_normal().z(), 1.0, 1e-12);
}
