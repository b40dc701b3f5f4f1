// The swept tube: closed and outward, the exact volume of an elliptic prism when straight,
// Pappus's volume when bent into an arc, passing through its points, its width where asked, and
// refusing bad input.
#include "spinesim/mesh/tube.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sm = spinesim::mesh;
using Eigen::Vector3d;

TEST(Tube, StraightTubeIsAClosedEllipticPrismOfExactVolume) {
  sm::TubeOptions o;
  o.sides = 16;
  o.rings_per_segment = 5;
  o.width_direction = Vector3d::UnitX();
  const sm::TriSurface s = sm::tube_surface(
      {Vector3d(0, 0, 0), Vector3d(0, 40, 0), Vector3d(0, 100, 0)}, {15, 15, 15}, {5, 5, 5}, o);
  const sm::SurfaceCheck c = sm::check_surface(s);
  EXPECT_TRUE(c.closed) << c.boundary_edges << " boundary edges";
  EXPECT_TRUE(c.oriented);
  // A 16-gon inscribed in the ellipse: area (n/2)·a·b·sin(2π/n); times the length.
  const double area = 16 / 2.0 * 15 * 5 * std::sin(2 * M_PI / 16);
  EXPECT_NEAR(c.volume_mm3, area * 100, 1e-9 * area * 100);
  // Width along x, depth along z.
  EXPECT_NEAR(s.V.col(0).maxCoeff(), 15, 1e-12);
  EXPECT_NEAR(s.V.col(2).maxCoeff(), 5 * std::sin(2 * M_PI * 4 / 16), 1e-12);
  EXPECT_NEAR(s.V.col(1).minCoeff(), 0, 1e-12);
  EXPECT_NEAR(s.V.col(1).maxCoeff(), 100, 1e-12);
}

TEST(Tube, ArcHasPappussVolumeAndPassesThroughItsPoints) {
  // Points on a quarter circle of radius 100 mm; a round tube of radius 4 mm around it.
  std::vector<Vector3d> p;
  for (int i = 0; i <= 6; ++i) {
    const double a = M_PI / 2 * i / 6;
    p.emplace_back(100 * std::cos(a), 100 * std::sin(a), 0);
  }
  sm::TubeOptions o;
  o.sides = 24;
  o.rings_per_segment = 10;
  const sm::TriSurface s =
      sm::tube_surface(p, std::vector<double>(p.size(), 4), std::vector<double>(p.size(), 4), o);
  const sm::SurfaceCheck c = sm::check_surface(s);
  EXPECT_TRUE(c.closed && c.oriented);
  // The Catmull–Rom curve's length is the arc's to well under 1 %; the 24-gon's area is
  // 0.989 of the circle's.
  const double polygon = 24 / 2.0 * 16 * std::sin(2 * M_PI / 24);
  EXPECT_NEAR(c.volume_mm3, polygon * 100 * M_PI / 2, 0.01 * polygon * 100 * M_PI / 2);
  // Every given point is a ring's centre.
  for (std::size_t i = 0; i < p.size(); ++i) {
    Vector3d centre = Vector3d::Zero();
    for (int j = 0; j < o.sides; ++j)
      centre += s.V.row(Eigen::Index(i) * 10 * o.sides + j).transpose();
    EXPECT_LT((centre / o.sides - p[i]).norm(), 1e-9) << i;
  }
}

TEST(Tube, RefusesBadInput) {
  const Vector3d a(0, 0, 0), b(0, 10, 0);
  EXPECT_THROW(sm::tube_surface({a}, {1}, {1}), std::invalid_argument);
  EXPECT_THROW(sm::tube_surface({a, b}, {1}, {1, 1}), std::invalid_argument);
  EXPECT_THROW(sm::tube_surface({a, b}, {1, 0}, {1, 1}), std::invalid_argument);
  EXPECT_THROW(sm::tube_surface({a, a}, {1, 1}, {1, 1}), std::invalid_argument);
  EXPECT_THROW(sm::tube_surface({a, Vector3d(0, NAN, 0)}, {1, 1}, {1, 1}), std::invalid_argument);
  sm::TubeOptions o;
  o.sides = 2;
  EXPECT_THROW(sm::tube_surface({a, b}, {1, 1}, {1, 1}, o), std::invalid_argument);
}
