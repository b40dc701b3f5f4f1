// Disc between two real vertebrae (ArtiSynth L4/L5, metres, z up) and the bad-input cases.
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mesh/vertebra_disc.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>

using namespace spinesim::mesh;

namespace {
const std::string kDir = std::string(SPINESIM_TESTDATA_DIR) + "/artisynth-lss";

TriSurface load(const std::string& name) {
  return read_surface(kDir + "/" + name, 1000.0, UpAxis::z);
}

#define SKIP_WITHOUT_DATA() \
  if (!std::filesystem::exists(kDir + "/L4_body.obj")) GTEST_SKIP() << "no test data in " << kDir

MeshOptions coarse() {
  MeshOptions o;
  o.cell_size_mm = 2.5;
  return o;
}

void check_disc(const TriSurface& l5, const TriSurface& l4, const char* what) {
  VertebraDiscInfo info;
  const auto t0 = std::chrono::steady_clock::now();
  const TetMesh m = mesh_disc_between_vertebrae(l5, l4, coarse(), {}, &info);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto q = quality_report(m, info.volume_mm3);
  std::printf(
      "%s: height %.2f mm (%.2f..%.2f), area %.0f mm^2, %.1f x %.1f mm, %lld tets, %.2f s, "
      "dihedral %.1f..%.1f, volume %.0f vs %.0f mm^3 (%.2f %%)\n",
      what, info.center_height_mm, info.min_height_mm, info.max_height_mm, info.footprint_area_mm2,
      info.width_mm, info.depth_mm, (long long)q.tets, s, q.min_dihedral_deg, q.max_dihedral_deg,
      q.volume_mm3, info.volume_mm3, 100 * q.volume_error());
  EXPECT_NO_THROW(validate(m));
  EXPECT_NO_THROW(require_endplate_labels(m));
  EXPECT_GT(q.wall_nodes, 0);
  EXPECT_GT(q.annulus_tets, 0);
  EXPECT_GT(q.nucleus_tets, 0);
  EXPECT_GT(info.center_height_mm, 5.0);
  EXPECT_LT(info.center_height_mm, 20.0);
  EXPECT_GT(info.footprint_area_mm2, 1000.0);
  EXPECT_LT(info.footprint_area_mm2, 2500.0);
  EXPECT_LT(std::abs(q.volume_error()), 0.03);
  // The disc sits between the vertebrae: inferior nodes below superior nodes along the axis.
  const Eigen::Vector3d axis = m.frame.axes.col(1);
  double inf_mean = 0, sup_mean = 0;
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    const double s_ax = (m.V.row(v).transpose() - m.frame.origin_mm).dot(axis);
    if (m.surface(v) == 1) inf_mean += s_ax / double(q.inferior_nodes);
    if (m.surface(v) == 2) sup_mean += s_ax / double(q.superior_nodes);
  }
  EXPECT_LT(inf_mean, 0.0);
  EXPECT_GT(sup_mean, 0.0);
  EXPECT_GT(axis.y(), 0.8);  // roughly vertical
}
}  // namespace

TEST(VertebraDisc, BetweenL5AndL4Bodies) {
  SKIP_WITHOUT_DATA();
  check_disc(load("L5_body.obj"), load("L4_body.obj"), "bodies");
}

TEST(VertebraDisc, BetweenWholeL5AndL4) {
  SKIP_WITHOUT_DATA();
  check_disc(load("L5_Schrumpfverpacken.obj"), load("L4_Schrumpfverpacken.obj"), "whole vertebrae");
}

TEST(VertebraDisc, RefusesBadInput) {
  TriSurface empty;
  TriSurface tri;
  tri.V = Eigen::MatrixX3d::Identity(3, 3);
  tri.F = Eigen::MatrixX3i(1, 3);
  tri.F << 0, 1, 2;
  EXPECT_THROW(analyse_vertebra_pair(empty, tri), std::invalid_argument);
  EXPECT_THROW(analyse_vertebra_pair(tri, empty), std::invalid_argument);
  SKIP_WITHOUT_DATA();
  const TriSurface l4 = load("L4_body.obj"), l5 = load("L5_body.obj");
  EXPECT_THROW(analyse_vertebra_pair(l5, l5), std::invalid_argument);  // the same vertebra twice
  EXPECT_THROW(analyse_vertebra_pair(l4, l5), std::invalid_argument);  // swapped order
  try {
    analyse_vertebra_pair(l4, l5);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not above"), std::string::npos) << e.what();
  }
  // Pulled 60 mm apart: gap absurd.
  TriSurface far = l4;
  far.V.col(1).array() += 60.0;
  EXPECT_THROW(analyse_vertebra_pair(l5, far), std::invalid_argument);
  // Shifted sideways by 80 mm: the superior is not above / the footprints do not overlap.
  TriSurface aside = l4;
  aside.V.col(0).array() += 80.0;
  EXPECT_THROW(analyse_vertebra_pair(l5, aside), std::invalid_argument);
}

// A hole in an endplate, as a segmentation leaves it: with one triangle (the last face of L5's
// file) missing, the disc still meshes — the hole's columns take their neighbours' heights and
// the count is reported — where CGAL's rim protection used to run forever.
TEST(VertebraDisc, OneTriangleHoleInAnEndplateIsFilledAndReported) {
  SKIP_WITHOUT_DATA();
  TriSurface l5 = load("L5_body.obj");
  const TriSurface l4 = load("L4_body.obj");
  const VertebraDiscInfo closed = analyse_vertebra_pair(l5, l4);
  EXPECT_EQ(closed.filled_columns, 0);
  Eigen::MatrixX3i F = l5.F.topRows(l5.F.rows() - 1);
  l5.F = F;
  VertebraDiscInfo info;
  const TetMesh m = mesh_disc_between_vertebrae(l5, l4, coarse(), {}, &info);
  EXPECT_GT(info.filled_columns, 0);
  EXPECT_NEAR(info.filled_area_mm2, double(info.filled_columns) * 0.25 * 0.25, 1e-12);
  EXPECT_NEAR(info.volume_mm3, closed.volume_mm3, 0.01 * closed.volume_mm3);  // a tiny hole
  EXPECT_NO_THROW(require_endplate_labels(m));
}

// A rim over a larger open part of the endplate is refused in seconds, saying where.
TEST(VertebraDisc, RimOverAnOpenEndplateIsRefusedNotAHang) {
  SKIP_WITHOUT_DATA();
  TriSurface l5 = load("L5_body.obj"), l4 = load("L4_body.obj");
  for (TriSurface* s : {&l5, &l4}) {
    Eigen::MatrixX3i F = s->F.topRows(s->F.rows() - 50);
    s->F = F;
  }
  try {
    mesh_disc_between_vertebrae(l5, l4, coarse(), {});
    ADD_FAILURE() << "an open endplate under the rim was meshed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("open or broken under the disc's rim"), std::string::npos)
        << e.what();
  }
}

// A surface in the wrong units (cm read as m: 100x too big) is refused before any allocation.
TEST(VertebraDisc, SurfacesInTheWrongUnitsAreRefusedByTheirFootprint) {
  SKIP_WITHOUT_DATA();
  TriSurface l5 = load("L5_body.obj"), l4 = load("L4_body.obj");
  l5.V *= 100.0;
  l4.V *= 100.0;
  try {
    analyse_vertebra_pair(l5, l4);
    ADD_FAILURE() << "a 5 m footprint was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("wrong units"), std::string::npos) << e.what();
  }
}
