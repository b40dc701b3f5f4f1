// Parametric vertebrae: the solids are where the spine model puts them, their surfaces are
// closed and outward, and sizes follow data/vertebra_morphometry.csv.
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/vertebra_geometry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <random>

namespace sm = spinesim::mesh;

namespace {

const std::string kData = SPINESIM_DATA_DIR;

// Volume of the solid by Monte Carlo over its bounding cube: the oracle for the meshed volume.
double monte_carlo_volume(const sm::ParametricVertebra& v, int samples) {
  std::mt19937 rng(7);
  const Eigen::Vector3d c = v.bounding_center_mm();
  const double r = v.bounding_radius_mm();
  std::uniform_real_distribution<double> u(-r, r);
  int inside = 0;
  for (int i = 0; i < samples; ++i)
    inside += v.contains(c + Eigen::Vector3d(u(rng), u(rng), u(rng))) ? 1 : 0;
  return std::pow(2 * r, 3) * inside / samples;
}

}  // namespace

TEST(VertebraGeometry, EighteenBodiesTopToBottom) {
  const auto& names = sm::scene_body_names();
  ASSERT_EQ(names.size(), 18u);
  EXPECT_EQ(names.front(), "T1");
  EXPECT_EQ(names.back(), "S1");
  double previous_y = 1e9;
  for (const auto& name : names) {
    const auto v = sm::parametric_vertebra(name, kData);
    EXPECT_LT(v.frame.origin_mm.y(), previous_y) << name;
    previous_y = v.frame.origin_mm.y();
    EXPECT_GT(v.body_height_mm, 8.0) << name;
    EXPECT_LT(v.body_height_mm, 40.0) << name;
    EXPECT_NEAR(v.frame.axes.determinant(), 1.0, 1e-12) << name;
    EXPECT_GT(v.frame.axes(2, 2), 0.5) << name << ": z must point anterior";
  }
  EXPECT_THROW(sm::parametric_vertebra("C7", kData), std::invalid_argument);
}

TEST(VertebraGeometry, BodyEndplatesAreTheDiscOutlines) {
  // L4's lower endplate is the L4-L5 disc's upper outline, one disc height/2 above the joint.
  const auto v = sm::parametric_vertebra("L4", kData);
  const auto disc = sm::disc_dimensions("L4-L5", kData);
  const auto frame = sm::disc_frame_in_spine("L4-L5", kData);
  EXPECT_DOUBLE_EQ(v.lower_width_mm, disc.upper_width_mm);
  EXPECT_DOUBLE_EQ(v.lower_depth_mm, disc.upper_depth_mm);
  const Eigen::Vector3d bottom = v.frame.origin_mm - 0.5 * v.body_height_mm * v.frame.axes.col(1);
  EXPECT_LT((bottom - (frame.origin_mm + 0.5 * disc.height_mm * frame.axes.col(1))).norm(), 1e-9);
  // The body's centre is inside, the canal (just behind the posterior wall) is not, the
  // spinous process's tip region is.
  EXPECT_TRUE(v.contains(Eigen::Vector3d::Zero()));
  const auto m = sm::vertebra_morphometry("L4", kData);
  const double wall = -0.5 * v.lower_depth_mm;
  EXPECT_FALSE(v.contains(Eigen::Vector3d(0, 0, wall - 0.5 * m.canal_depth_mm)));
  EXPECT_TRUE(v.contains(v.parts.back().b));
}

TEST(VertebraGeometry, SweptBoxDistanceIsExactOnItsAxes) {
  sm::SweptBox b;
  b.a = {0, 0, 0};
  b.b = {10, 0, 0};
  b.up = {0, 1, 0};
  b.half_width_mm = 2;
  b.half_height_mm = 3;
  b.rounding_mm = 1;
  // Along x the box reaches 2 (= min half size) past each end; y half 3, z half 2.
  EXPECT_NEAR(b.signed_distance({5, 0, 0}), -2.0, 1e-12);
  EXPECT_NEAR(b.signed_distance({5, 5, 0}), 2.0, 1e-12);
  EXPECT_NEAR(b.signed_distance({5, 0, 4}), 2.0, 1e-12);
  EXPECT_NEAR(b.signed_distance({14, 0, 0}), 2.0, 1e-12);
}

TEST(VertebraGeometry, MeshedSurfaceIsClosedOrientedAndHasTheSolidsVolume) {
  // (the sacrum's closure is checked by tests/cli/test_cli_haptics.cpp, MeshVertebrae…)
  for (const char* name : {"T6", "L3"}) {
    const auto v = sm::parametric_vertebra(name, kData);
    const auto s = sm::mesh_vertebra(v, 3000);
    const auto check = sm::check_surface(s.surface);
    EXPECT_TRUE(check.closed) << name << ": " << check.boundary_edges << " boundary, "
                              << check.nonmanifold_edges << " non-manifold edges";
    EXPECT_TRUE(check.oriented) << name;
    EXPECT_GT(check.volume_mm3, 0) << name;
    EXPECT_GT(s.surface.F.rows(), 3000 * 0.7) << name;
    EXPECT_LT(s.surface.F.rows(), 3000 * 1.4) << name;
    const double mc = monte_carlo_volume(v, 150000);  // ±1.2 % (one sigma) for these solids
    EXPECT_NEAR(check.volume_mm3, mc, 0.05 * mc) << name;
  }
}

TEST(VertebraGeometry, BoundarySurfaceOfOneTetIsOutward) {
  sm::TetMesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  const auto s = sm::boundary_surface(m);
  const auto check = sm::check_surface(s);
  EXPECT_TRUE(check.oriented);
  EXPECT_NEAR(check.volume_mm3, 1.0 / 6.0, 1e-15);
}

TEST(VertebraGeometry, ObjRoundTrip) {
  const auto v = sm::parametric_vertebra("T1", kData);
  const auto s = sm::mesh_vertebra(v, 1000);
  const std::string dir = std::string(SPINESIM_TEST_TMP) + "/vertebra";
  std::filesystem::create_directories(dir);
  sm::write_obj(dir + "/T1.obj", s.surface, "T1");
  const auto back = sm::read_surface(dir + "/T1.obj", 1.0, sm::UpAxis::y);
  ASSERT_EQ(back.F.rows(), s.surface.F.rows());
  EXPECT_LT((back.V - s.surface.V).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(VertebraGeometry, RefusesAbsurdResolutions) {
  const auto v = sm::parametric_vertebra("L1", kData);
  EXPECT_THROW(sm::mesh_vertebra(v, 10), std::invalid_argument);
  EXPECT_THROW(sm::mesh_vertebra(v, 100000000), std::invalid_argument);
}
