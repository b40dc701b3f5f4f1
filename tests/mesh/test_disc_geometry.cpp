// Kidney outline and lofted parametric disc: extents, area, 40 % nucleus, posterior concavity,
// loft volume — each checked by an independent computation.
#include "spinesim/common/constants.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace spinesim::mesh;
using spinesim::kPi;

namespace {

// Shoelace area and centroid of a closed polygon in (x, z).
void polygon_area_centroid(const std::vector<Eigen::Vector2d>& p, double& area,
                           Eigen::Vector2d& c) {
  area = 0;
  c.setZero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d& a = p[i];
    const Eigen::Vector2d& b = p[(i + 1) % p.size()];
    const double cr = a.x() * b.y() - b.x() * a.y();
    area += 0.5 * cr;
    c += (a + b) * cr / 6.0;
  }
  c /= area;
}
}  // namespace

TEST(KidneyOutline, ExtentsAreExactlyWidthAndDepth) {
  for (auto [w, d] : {std::pair{46.6, 35.0}, std::pair{24.5, 17.0}, std::pair{10.0, 10.0}}) {
    const KidneyOutline o(w, d);
    double xmin = 1e9, xmax = -1e9, zmin = 1e9, zmax = -1e9;
    for (const auto& p : o.sample(200000)) {
      xmin = std::min(xmin, p.x());
      xmax = std::max(xmax, p.x());
      zmin = std::min(zmin, p.y());
      zmax = std::max(zmax, p.y());
    }
    EXPECT_NEAR(xmax - xmin, w, 1e-7 * w);
    EXPECT_NEAR(zmax - zmin, d, 1e-7 * d);
    EXPECT_NEAR(xmax, -xmin, 1e-9);  // mirror symmetric about the sagittal plane
    EXPECT_NEAR(zmin, o.min_z_mm(), 1e-7 * d);
  }
}

TEST(KidneyOutline, AreaAndCentroidMatchAFinePolygon) {
  const KidneyOutline o(46.6, 35.0);
  double area;
  Eigen::Vector2d c;
  polygon_area_centroid(o.sample(1 << 16), area, c);
  // The inscribed polygon's area converges as O(n^-2): relative error ~ 1e-9 here.
  EXPECT_NEAR(o.area_mm2(), area, 1e-7 * area);
  EXPECT_NEAR(c.norm(), 0.0, 1e-6);
  EXPECT_NEAR(o.centroid_mm().norm(), 0.0, 1e-10);
  // Area scales with width x depth.
  EXPECT_NEAR(KidneyOutline(2 * 46.6, 35.0).area_mm2(), 2 * o.area_mm2(), 1e-9 * o.area_mm2());
}

TEST(KidneyOutline, NucleusIsFortyPercentByMonteCarlo) {
  const KidneyOutline o(46.6, 35.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(-23.3, 23.3), uz(o.min_z_mm(), o.min_z_mm() + 35.0);
  const int n = 400000;
  int inside = 0, nucleus = 0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d q(ux(rng), uz(rng));
    if (o.contains(q)) {
      ++inside;
      if (o.nucleus_contains(q)) ++nucleus;
    }
    if (o.nucleus_contains(q)) EXPECT_TRUE(o.contains(q));
  }
  const double box = 46.6 * 35.0;
  const double area_mc = box * inside / n;
  const double sigma = box * std::sqrt(double(inside) / n * (1 - double(inside) / n) / n);
  EXPECT_NEAR(area_mc, o.area_mm2(), 4 * sigma);
  const double frac = double(nucleus) / inside;
  EXPECT_NEAR(frac, 0.4, 4 * std::sqrt(0.4 * 0.6 / inside));
  // Exact: the scaled polygon has 40 % of the area.
  double a1, a2;
  Eigen::Vector2d c;
  polygon_area_centroid(o.sample(4096), a1, c);
  polygon_area_centroid(o.sample(4096, std::sqrt(0.4)), a2, c);
  EXPECT_NEAR(a2 / a1, 0.4, 1e-12);
}

TEST(KidneyOutline, PosteriorMidpointIsConcave) {
  const KidneyOutline o(46.6, 35.0);
  // Three neighbouring points around the posterior midpoint (θ = -90°): for a
  // counter-clockwise curve a concave vertex turns clockwise (negative cross product).
  const double e = 0.01;
  const Eigen::Vector2d a = o.point(-kPi / 2 - e), b = o.point(-kPi / 2), c = o.point(-kPi / 2 + e);
  const Eigen::Vector2d u = b - a, v = c - b;
  EXPECT_LT(u.x() * v.y() - u.y() * v.x(), 0.0);
  EXPECT_LT(o.signed_curvature(-kPi / 2), 0.0);
  // The curve is convex anteriorly and laterally, and counter-clockwise overall.
  EXPECT_GT(o.signed_curvature(kPi / 2), 0.0);
  EXPECT_GT(o.signed_curvature(0.0), 0.0);
  // The notch is a real dent: the midpoint lies anterior to the posterior-most points.
  EXPECT_GT(b.y(), o.min_z_mm() + 1.5);  // ≈ 2.5 mm for a 35 mm depth
}

TEST(ParametricDisc, LoftVolumeMatchesQuadratureAndLabels) {
  DiscDimensions d{"test", 44.0, 33.0, 48.0, 36.0, 11.3};
  const ParametricDisc disc(d);
  // Independent: Simpson over y of the outline areas (a quadratic in y, so Simpson is exact).
  const double h = d.height_mm;
  double simpson = 0;
  const int n = 8;
  for (int k = 0; k <= n; ++k) {
    const double y = -h / 2 + h * k / n;
    const double wgt = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
    simpson += wgt * disc.outline_at(y).area_mm2();
  }
  simpson *= h / (3 * n);
  EXPECT_NEAR(disc.volume_mm3(), simpson, 1e-9 * simpson);
  EXPECT_NEAR(parametric_disc_volume(d), simpson, 1e-9 * simpson);
  // Labels: outside above/below, nucleus at the centre, annulus near the lateral rim.
  EXPECT_EQ(disc.label({0, 0, 0}), 2);
  EXPECT_EQ(disc.label({0, h / 2 + 1e-6, 0}), 0);
  EXPECT_EQ(disc.label({0, -h / 2 - 1e-6, 0}), 0);
  EXPECT_EQ(disc.label({0.5 * 44.0 - 0.5, -h / 2 + 1e-3, 0}), 1);
  EXPECT_EQ(disc.label({0.5 * 48.0 + 0.5, h / 2 - 1e-3, 0}), 0);
  // Feature polylines: closed, on the planes, on the outlines.
  const auto lines = disc.feature_polylines(0.5);
  ASSERT_EQ(lines.size(), 4u);
  for (const auto& l : lines) {
    EXPECT_EQ((l.front() - l.back()).norm(), 0.0);
    EXPECT_NEAR(std::abs(l.front().y()), h / 2, 1e-12);
  }
  EXPECT_THROW(ParametricDisc(DiscDimensions{"bad", 0, 1, 1, 1, 1}), std::invalid_argument);
}
