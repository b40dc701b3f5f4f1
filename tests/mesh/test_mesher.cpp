// CGAL Mesh_3 disc meshing: validity, regions, surface labels, volume, reproducibility,
// placement, and the quality target at 1.5 mm (L4-L5 dimensions written here, not read).
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

using namespace spinesim::mesh;

namespace {
// L4-L5: L5 upper endplate 47.3 mm wide, L4 lower 46.6 mm (Panjabi 1992); depth ~35 mm;
// height 11.3 mm (Twomey 1985).
DiscDimensions l4_l5() { return {"L4-L5", 47.3, 35.5, 46.6, 35.0, 11.3}; }

MeshOptions coarse() {
  MeshOptions o;
  o.cell_size_mm = 3.0;
  return o;
}

const TetMesh& coarse_disc() {
  static const TetMesh m = mesh_parametric_disc(l4_l5(), coarse());
  return m;
}

double region_volume(const TetMesh& m, int region) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    if (m.region(t) == region) v += tet_volume(m, t);
  return v;
}
}  // namespace

TEST(Mesher, CoarseDiscIsValidWithTwoRegions) {
  const TetMesh& m = coarse_disc();
  ASSERT_GT(m.num_tets(), 100);
  EXPECT_NO_THROW(validate(m));  // every tet positively oriented, labels sized
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) ASSERT_GT(tet_volume(m, t), 0.0);
  const double total = mesh_volume(m);
  const double nucleus = region_volume(m, int(Region::nucleus));
  EXPECT_GT(region_volume(m, int(Region::annulus)), 0.0);
  EXPECT_NEAR(nucleus / total, 0.4, 0.03);
  const double exact = parametric_disc_volume(l4_l5());
  EXPECT_NEAR(total / exact, 1.0, 0.02);
}

TEST(Mesher, SurfaceLabelsSitOnTheirSurfaces) {
  const TetMesh& m = coarse_disc();
  EXPECT_NO_THROW(require_endplate_labels(m));
  const double half = 0.5 * l4_l5().height_mm;
  int wall = 0, sup = 0, inf = 0;
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    switch (Surface(m.surface(v))) {
      case Surface::superior_endplate:
        ++sup;
        EXPECT_NEAR(m.V(v, 1), half, 1e-3);
        break;
      case Surface::inferior_endplate:
        ++inf;
        EXPECT_NEAR(m.V(v, 1), -half, 1e-3);
        break;
      case Surface::outer_wall:
        ++wall;
        EXPECT_LT(std::abs(m.V(v, 1)), half);
        break;
      default:
        EXPECT_LT(std::abs(m.V(v, 1)), half);
        break;
    }
  }
  EXPECT_GT(sup, 20);
  EXPECT_GT(inf, 20);
  EXPECT_GT(wall, 20);
  // Every node on the top plane is a superior node (rim nodes carry the endplate label).
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
    if (std::abs(m.V(v, 1) - half) < 1e-9) EXPECT_EQ(m.surface(v), int(Surface::superior_endplate));
}

TEST(Mesher, SameSeedSameMesh) {
  const TetMesh again = mesh_parametric_disc(l4_l5(), coarse());
  const TetMesh& m = coarse_disc();
  ASSERT_EQ(again.num_vertices(), m.num_vertices());
  ASSERT_EQ(again.num_tets(), m.num_tets());
  EXPECT_EQ((again.V - m.V).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE((again.T.array() == m.T.array()).all());
  EXPECT_TRUE((again.surface.array() == m.surface.array()).all());
}

TEST(Mesher, PlacementMovesTheDiscRigidly) {
  DiscFrame f;
  f.origin_mm = Eigen::Vector3d(3.0, 420.0, -12.0);
  f.axes = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const TetMesh placed = mesh_parametric_disc(l4_l5(), coarse(), f);
  const TetMesh& m = coarse_disc();
  ASSERT_EQ(placed.num_vertices(), m.num_vertices());
  const Eigen::MatrixX3d expect = (m.V * f.axes.transpose()).rowwise() + f.origin_mm.transpose();
  EXPECT_LT((placed.V - expect).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(placed.frame.origin_mm.isApprox(f.origin_mm));
  EXPECT_NO_THROW(validate(placed));
  EXPECT_NEAR(mesh_volume(placed), mesh_volume(m), 1e-6 * mesh_volume(m));
}

TEST(Mesher, LabeledCylinder) {
  LabeledBody cyl;  // radius 5, length 20 along y: a generic (non-disc) body
  cyl.label = [](const Eigen::Vector3d& p) {
    return (p.x() * p.x() + p.z() * p.z() <= 25.0 && std::abs(p.y()) <= 10.0) ? 7 : 0;
  };
  cyl.bounding_radius_mm = 15.0;
  MeshOptions o;
  o.cell_size_mm = 2.0;
  const TetMesh m = mesh_labeled_body(cyl, o);
  EXPECT_NO_THROW(validate(m));
  EXPECT_TRUE((m.region.array() == 7).all());
  EXPECT_TRUE((m.surface.array() == 0 || m.surface.array() == 3).all());
  EXPECT_NEAR(mesh_volume(m) / (M_PI * 25.0 * 20.0), 1.0, 0.05);  // no rim protection here
  LabeledBody empty = cyl;
  empty.label = [](const Eigen::Vector3d&) { return 0; };
  EXPECT_THROW(mesh_labeled_body(empty, o), std::runtime_error);
}

// The target: L4-L5 at cell size 1.5 mm -> min dihedral >= 10°, volume within 2 %.
TEST(Mesher, L4L5AtOnePointFiveMillimetres) {
  MeshOptions o;
  o.cell_size_mm = 1.5;
  const auto t0 = std::chrono::steady_clock::now();
  const TetMesh m = mesh_parametric_disc(l4_l5(), o);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto q = quality_report(m, parametric_disc_volume(l4_l5()));
  std::printf("L4-L5 @ 1.5 mm: %lld tets, %.2f s, dihedral %.1f..%.1f deg, volume error %.3f %%\n",
              (long long)q.tets, seconds, q.min_dihedral_deg, q.max_dihedral_deg,
              100 * q.volume_error());
  EXPECT_GE(q.min_dihedral_deg, 10.0);
  EXPECT_LT(std::abs(q.volume_error()), 0.02);
  EXPECT_NEAR(double(q.annulus_tets + q.nucleus_tets), double(q.tets), 0.0);
}

// The size estimate that guards the mesher against absurd resolutions is an estimate of what
// CGAL makes: within a factor of two of the real count (tetrahedra + boundary triangles) at two
// resolutions.
TEST(Mesher, ExpectedElementsTracksTheRealCount) {
  for (double cell : {3.0, 2.0}) {
    MeshOptions o;
    o.cell_size_mm = cell;
    const TetMesh m = mesh_parametric_disc(l4_l5(), o);
    const auto q = quality_report(m, parametric_disc_volume(l4_l5()));
    std::map<std::array<Eigen::Index, 3>, int> faces;
    for (Eigen::Index t = 0; t < m.num_tets(); ++t)
      for (int k = 0; k < 4; ++k) {
        std::array<Eigen::Index, 3> f{m.T(t, (k + 1) % 4), m.T(t, (k + 2) % 4),
                                      m.T(t, (k + 3) % 4)};
        std::sort(f.begin(), f.end());
        ++faces[f];
      }
    double boundary = 0;
    for (const auto& [f, n] : faces) boundary += n == 1;
    const double real = double(q.tets) + boundary;
    const double est = expected_elements(parametric_disc_volume(l4_l5()), 30.0, o);
    std::printf("cell %.1f mm: %lld tets + %.0f boundary triangles, estimate %.0f\n", cell,
                (long long)q.tets, boundary, est);
    EXPECT_GT(est, 0.5 * real) << "cell " << cell;
    EXPECT_LT(est, 2.0 * real) << "cell " << cell;
  }
}

// Absurd resolutions are refused before any allocation, naming the estimate and the limit.
TEST(Mesher, ResolutionsBeyondTheElementLimitAreRefusedAtOnce) {
  for (const auto& [cell, distance, facet] :
       {std::tuple{1e-6, 0.1, 0.0}, std::tuple{2.0, 1e-9, 0.0}, std::tuple{2.0, 0.1, 1e-6}}) {
    MeshOptions o;
    o.cell_size_mm = cell;
    o.facet_distance_mm = distance;
    o.facet_size_mm = facet;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      mesh_parametric_disc(l4_l5(), o);
      ADD_FAILURE() << "meshed at cell " << cell;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("more than the limit of"), std::string::npos)
          << e.what();
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  }
  MeshOptions raised;  // the limit is the user's to raise
  raised.cell_size_mm = 3.0;
  raised.max_elements = 100;
  EXPECT_THROW(mesh_parametric_disc(l4_l5(), raised), std::invalid_argument);
}
