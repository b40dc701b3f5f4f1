// Structured (sweep) disc mesh: conformity (every interior face shared by two tets, closed
// boundary), counts and labels, volume convergence to the exact disc, nucleus share, quality
// on all 17 levels, placement, and bad options.
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>

using namespace spinesim::mesh;

namespace {
const std::string kData = SPINESIM_DATA_DIR;

// L4-L5 as in test_mesher.cpp (Panjabi 1992, Twomey 1985); written here, not read.
DiscDimensions l4_l5() { return {"L4-L5", 47.3, 35.5, 46.6, 35.0, 11.3}; }

using Face = std::array<int, 3>;

// Sorted vertex triple of every tet face -> how many tets share it.
std::map<Face, int> face_counts(const TetMesh& m) {
  std::map<Face, int> count;
  static const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (const auto& f : faces) {
      Face key{m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  return count;
}

double region_volume(const TetMesh& m, Region r) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    if (m.region(t) == int(r)) v += tet_volume(m, t);
  return v;
}

double volume_error(const DiscDimensions& d, const StructuredDiscOptions& o) {
  return mesh_volume(mesh_structured_disc(d, o)) / parametric_disc_volume(d) - 1.0;
}
}  // namespace

TEST(StructuredDisc, CountsMatchTheSweep) {
  for (const StructuredDiscOptions o :
       {StructuredDiscOptions{}, StructuredDiscOptions{6, 2, 1}, StructuredDiscOptions{24, 5, 3}}) {
    const TetMesh m = mesh_structured_disc(l4_l5(), o);
    EXPECT_NO_THROW(validate(m));
    EXPECT_EQ(m.num_vertices(), (o.layers + 1) * (1 + o.rings * o.sectors));
    EXPECT_EQ(m.num_tets(), 3 * o.layers * o.sectors * (2 * o.rings - 1));
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) ASSERT_GT(tet_volume(m, t), 0.0);
  }
}

TEST(StructuredDisc, ConformingWithAClosedBoundary) {
  for (const StructuredDiscOptions o :
       {StructuredDiscOptions{}, StructuredDiscOptions{7, 2, 1}, StructuredDiscOptions{13, 4, 3}}) {
    const TetMesh m = mesh_structured_disc(l4_l5(), o);
    const auto count = face_counts(m);
    std::set<std::array<int, 2>> edges;
    std::set<int> verts;
    std::map<std::array<int, 2>, int> edge_use;
    long boundary = 0;
    for (const auto& [f, c] : count) {
      ASSERT_LE(c, 2) << "face shared by more than two tets";
      if (c != 1) continue;
      ++boundary;
      for (int i = 0; i < 3; ++i) {
        verts.insert(f[i]);
        std::array<int, 2> e{f[i], f[(i + 1) % 3]};
        std::sort(e.begin(), e.end());
        edges.insert(e);
        ++edge_use[e];
      }
    }
    // Closed 2-manifold of genus 0: every boundary edge in two boundary triangles, V - E + F = 2.
    for (const auto& [e, c] : edge_use) ASSERT_EQ(c, 2);
    EXPECT_EQ(long(verts.size()) - long(edges.size()) + boundary, 2);
    // Boundary triangles: two endplate fans/annuli plus the wall.
    EXPECT_EQ(boundary, 2 * o.sectors * (2 * o.rings - 1) + 2 * o.sectors * o.layers);
    // A node carries a surface label exactly when it lies on the boundary.
    for (Eigen::Index v = 0; v < m.num_vertices(); ++v)
      EXPECT_EQ(m.surface(v) != 0, verts.count(int(v)) == 1) << "node " << v;
  }
}

TEST(StructuredDisc, LabelsFollowTheLayers) {
  const StructuredDiscOptions o{12, 3, 3};
  const TetMesh m = mesh_structured_disc(l4_l5(), o);
  const double half = 0.5 * l4_l5().height_mm;
  const auto q = quality_report(m);
  EXPECT_EQ(q.inferior_nodes, 1 + o.rings * o.sectors);
  EXPECT_EQ(q.superior_nodes, 1 + o.rings * o.sectors);
  EXPECT_EQ(q.wall_nodes, (o.layers - 1) * o.sectors);
  EXPECT_NO_THROW(require_endplate_labels(m));
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    const double y = m.V(v, 1);
    if (m.surface(v) == int(Surface::inferior_endplate)) EXPECT_EQ(y, -half);
    if (m.surface(v) == int(Surface::superior_endplate)) EXPECT_EQ(y, half);
    if (std::abs(std::abs(y) - half) > 1e-9) {
      EXPECT_NE(m.surface(v), int(Surface::inferior_endplate));
      EXPECT_NE(m.surface(v), int(Surface::superior_endplate));
    }
    if (m.surface(v) == int(Surface::outer_wall)) {
      // On the lofted outline at its height (within round-off of the bisection-free sample).
      const KidneyOutline o_y = ParametricDisc(l4_l5()).outline_at(y);
      const Eigen::Vector2d xz(m.V(v, 0), m.V(v, 2));
      EXPECT_TRUE(o_y.contains(xz * (1 - 1e-9)));
      EXPECT_FALSE(o_y.contains(xz * (1 + 1e-6)));
    }
  }
}

// Rim nodes on the outline, straight chords between them: the inscribed-polygon area error is
// second order (circle: 1 - sin(2π/n)/(2π/n) ≈ (2π/n)^2/6, 0.64 % at n = 32); the loft in y is
// integrated exactly (see MatchedAreaGivesTheExactVolume). Measured on L4-L5: -11.75 %, -2.83 %,
// -0.689 %, -0.171 %, -0.0427 % at 8 ... 128 sectors (ratio 4.15, 4.11, 4.03, 4.01).
TEST(StructuredDisc, VolumeConvergesToTheExactDisc) {
  double previous = 1.0;
  std::printf("sectors  volume error (L4-L5, 3 rings, 2 layers)\n");
  for (int sectors : {8, 16, 32, 64, 128}) {
    const double e = volume_error(l4_l5(), {sectors, 3, 2});
    std::printf("%7d  %+.4f %%\n", sectors, 100 * e);
    EXPECT_LT(e, 0.0);  // inscribed polygons: always short
    EXPECT_LT(std::abs(e), previous);
    if (sectors >= 16) EXPECT_NEAR(previous / std::abs(e), 4.0, 0.3);  // second order
    previous = std::abs(e);
  }
  EXPECT_LT(std::abs(volume_error(l4_l5(), {32, 3, 2})), 0.0075);  // measured 0.689 %
}

// The polygon stretched to the outline's area at every layer: the volume is exact up to the
// small change of the stretch between layers when an outline's depth/width ratio differs
// between the endplates (by <= 3e-4 in the shipped data). Measured worst over all 17 levels and
// 5 resolutions: 3.7e-6 (round-off when the ratios agree, e.g. L1-L2).
TEST(StructuredDisc, MatchedAreaGivesTheExactVolume) {
  for (const std::string& level : {"T4-T5", "L4-L5"}) {
    const DiscDimensions d = disc_dimensions(level, kData);
    for (int sectors : {6, 12, 40}) {
      StructuredDiscOptions o{sectors, 3, 2};
      o.match_area = true;
      const TetMesh m = mesh_structured_disc(d, o);
      EXPECT_NO_THROW(validate(m));
      EXPECT_NEAR(mesh_volume(m) / parametric_disc_volume(d), 1.0, 1e-5) << level << " " << sectors;
      EXPECT_NEAR(region_volume(m, Region::nucleus) / mesh_volume(m), kNucleusAreaFraction, 1e-12);
      EXPECT_NE(m.source.find("area-matched"), std::string::npos);
    }
  }
}

// Each ring is the same polygon scaled by s about the centroid, so the nucleus polygon has
// exactly 0.4 of the rim polygon's area at every height, and the sweep integrates both exactly:
// the share is 0.4 to round-off (measured |error| <= 2e-15 on all 17 levels).
TEST(StructuredDisc, NucleusHoldsFortyPercent) {
  for (const StructuredDiscOptions o :
       {StructuredDiscOptions{}, StructuredDiscOptions{8, 2, 1}, StructuredDiscOptions{32, 6, 4}}) {
    const TetMesh m = mesh_structured_disc(l4_l5(), o);
    const double share = region_volume(m, Region::nucleus) / mesh_volume(m);
    EXPECT_NEAR(share, kNucleusAreaFraction, 1e-12)
        << o.sectors << "x" << o.rings << "x" << o.layers;
    EXPECT_GT(region_volume(m, Region::annulus), 0.0);
  }
}

TEST(StructuredDisc, RingScalesPutOneRingOnTheNucleusBoundary) {
  for (int rings = 2; rings <= 8; ++rings) {
    const auto s = structured_ring_scales(rings);
    ASSERT_EQ(int(s.size()), rings);
    EXPECT_EQ(s.back(), 1.0);
    EXPECT_EQ(std::count(s.begin(), s.end(), std::sqrt(kNucleusAreaFraction)), 1);
    EXPECT_GT(s.front(), 0.0);
    for (int k = 1; k < rings; ++k) EXPECT_GT(s[k], s[k - 1]);
  }
}

// Defaults on every level: 360 tets each. Measured: min dihedral 18.89° (T4-T5, the thinnest
// disc; 22-24° on the lumbar ones), max 141.8°, volume -5.098 % on every level (the outlines
// are stretched copies of one curve, so the polygon's area share is level-independent).
TEST(StructuredDisc, AllSeventeenLevelsWithDefaults) {
  const StructuredDiscOptions o;
  long total = 0;
  double worst_dihedral = 180, worst_volume = 0;
  std::printf("level    tets nodes  min/max dihedral deg  max r/e  volume err\n");
  for (const std::string& level : disc_levels()) {
    const DiscDimensions d = disc_dimensions(level, kData);
    const TetMesh m = mesh_structured_disc(d, o, disc_frame_in_spine(level, kData));
    ASSERT_NO_THROW(validate(m)) << level;
    const auto q = quality_report(m, parametric_disc_volume(d));
    std::printf("%-7s %5lld %5lld  %6.2f / %6.2f        %5.2f   %+.3f %%\n", level.c_str(),
                (long long)q.tets, (long long)q.vertices, q.min_dihedral_deg, q.max_dihedral_deg,
                q.max_radius_edge_ratio, 100 * q.volume_error());
    total += q.tets;
    worst_dihedral = std::min(worst_dihedral, q.min_dihedral_deg);
    worst_volume = std::max(worst_volume, std::abs(q.volume_error()));
    EXPECT_GT(q.min_dihedral_deg, 18.5) << level;
    EXPECT_NEAR(q.volume_error(), -0.051, 0.001) << level;
  }
  std::printf("total %ld tets, min dihedral %.2f deg, worst volume error %.3f %%\n", total,
              worst_dihedral, 100 * worst_volume);
  EXPECT_EQ(total, 17L * 3 * o.layers * o.sectors * (2 * o.rings - 1));
}

TEST(StructuredDisc, PlacementMovesTheDiscRigidly) {
  const TetMesh local = mesh_structured_disc(l4_l5());
  DiscFrame f;
  f.origin_mm = Eigen::Vector3d(3.0, 420.0, -12.0);
  f.axes = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const TetMesh placed = mesh_structured_disc(l4_l5(), {}, f);
  const Eigen::MatrixX3d expect =
      (local.V * f.axes.transpose()).rowwise() + f.origin_mm.transpose();
  EXPECT_LT((placed.V - expect).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(placed.frame.origin_mm.isApprox(f.origin_mm));
  EXPECT_TRUE(placed.frame.axes.isApprox(f.axes));
  EXPECT_NO_THROW(validate(placed));
  EXPECT_NEAR(mesh_volume(placed), mesh_volume(local), 1e-9 * mesh_volume(local));
  // A mirrored frame still gives positively oriented tets.
  DiscFrame mirror;
  mirror.axes = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  const TetMesh mirrored = mesh_structured_disc(l4_l5(), {}, mirror);
  EXPECT_NO_THROW(validate(mirrored));
  EXPECT_NEAR(mesh_volume(mirrored), mesh_volume(local), 1e-9 * mesh_volume(local));
  EXPECT_NE(local.source.find("structured disc L4-L5"), std::string::npos);
}

TEST(StructuredDisc, BadOptionsAreRefused) {
  for (const StructuredDiscOptions o :
       {StructuredDiscOptions{5, 3, 2}, StructuredDiscOptions{16, 1, 2},
        StructuredDiscOptions{16, 0, 2}, StructuredDiscOptions{16, 3, 0},
        StructuredDiscOptions{-16, 3, 2}}) {
    try {
      mesh_structured_disc(l4_l5(), o);
      ADD_FAILURE() << "accepted " << o.sectors << "x" << o.rings << "x" << o.layers;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos);
      EXPECT_NE(what.find("sectors >= 6"), std::string::npos) << what;
    }
  }
  DiscDimensions bad = l4_l5();
  bad.height_mm = 0;
  EXPECT_THROW(mesh_structured_disc(bad), std::invalid_argument);
}

// The boundary of a disc: closed (every edge on exactly two boundary faces, in opposite
// directions: consistently oriented), outward (the divergence theorem gives back the mesh's
// volume), each face on the tet that owns it.
TEST(BoundaryFaces, ClosedOutwardAndOwned) {
  const TetMesh m = mesh_structured_disc(disc_dimensions("L4-L5", kData));
  Eigen::VectorXi owner;
  const Eigen::MatrixX3i F = boundary_faces(m.T, &owner);
  ASSERT_GT(F.rows(), 0);
  std::map<std::pair<int, int>, int> directed;
  double volume = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) ++directed[{F(f, k), F(f, (k + 1) % 3)}];
    const Eigen::Vector3d a = m.V.row(F(f, 0)), b = m.V.row(F(f, 1)), c = m.V.row(F(f, 2));
    volume += a.dot(b.cross(c)) / 6;  // signed volume of the cone from the origin
    int shared = 0;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 4; ++j) shared += F(f, k) == m.T(owner(f), j);
    EXPECT_EQ(shared, 3) << f;
  }
  for (const auto& [edge, n] : directed) {
    EXPECT_EQ(n, 1);
    EXPECT_EQ(directed.count({edge.second, edge.first}), 1u);
  }
  EXPECT_NEAR(volume, mesh_volume(m), 1e-9 * mesh_volume(m));
}
