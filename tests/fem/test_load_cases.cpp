// The named load cases against their anatomical meaning, on the FEM solution: flexion compresses
// the anterior annulus and extension the posterior one, compression moves the superior plate
// down, shear-ap moves it anteriorly, lateral bending (+Mz) tips the plate towards the body's
// right (−x), torsion (+My) turns it anticlockwise seen from above — in the disc frame of an
// upright disc and of the same disc placed in the spine (tilted), where every check is made on
// the displacement expressed in that disc's own axes. Swapping two cases, or forgetting the
// rotation into the spine frame, fails here.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace spinesim;

namespace {

struct PlateResponse {
  Eigen::Vector3d t, theta;  ///< plate translation (mm) and rotation (rad), disc frame
  double anterior_uy = 0, posterior_uy = 0, left_uy = 0,
         right_uy = 0;  ///< axial motion of plate edges, mm
};

/// The plate's response to `name` in the disc's own frame, and the axial displacement of the
/// superior-plate nodes at its anterior, posterior, left (+x) and right (−x) extremes.
PlateResponse respond(const mesh::TetMesh& m, const fem::DiscFem& fem, const std::string& name) {
  const fem::PlateSolution s = fem.solve_wrench(fem::global_wrench(fem::load_case(name), m.frame));
  const Eigen::Matrix3d& R = m.frame.axes;  // columns: lateral, axial, anterior (global)
  PlateResponse r;
  r.t = R.transpose() * s.plate_motion.head<3>();
  r.theta = R.transpose() * s.plate_motion.tail<3>();
  double zmax = -1e9, zmin = 1e9, xmax = -1e9, xmin = 1e9;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    if (m.surface(i) != int(mesh::Surface::superior_endplate)) continue;
    const Eigen::Vector3d p = R.transpose() * (m.V.row(i).transpose() - m.frame.origin_mm);
    const double uy = (R.transpose() * s.displacement_mm.row(i).transpose()).y();
    if (p.z() > zmax) zmax = p.z(), r.anterior_uy = uy;
    if (p.z() < zmin) zmin = p.z(), r.posterior_uy = uy;
    if (p.x() > xmax) xmax = p.x(), r.left_uy = uy;
    if (p.x() < xmin) xmin = p.x(), r.right_uy = uy;
  }
  return r;
}

void check_anatomy(const mesh::TetMesh& m) {
  const auto materials = mesh::load_material("real-disc", SPINESIM_DATA_DIR);
  const fem::DiscFem fem(m, materials, 1, fem::DiscFem::default_plate_center(m));
  const PlateResponse compression = respond(m, fem, "compression"),
                      tension = respond(m, fem, "tension");
  EXPECT_LT(compression.t.y(), 0) << "compression moves the superior plate down";
  EXPECT_GT(tension.t.y(), 0);
  EXPECT_GT(respond(m, fem, "shear-ap").t.z(), 0) << "shear-ap pushes the plate anteriorly";
  EXPECT_GT(respond(m, fem, "shear-lat").t.x(), 0)
      << "shear-lat pushes the plate towards +x (the body's left)";

  const PlateResponse flexion = respond(m, fem, "flexion"),
                      extension = respond(m, fem, "extension");
  EXPECT_GT(flexion.theta.x(), 0);
  EXPECT_LT(flexion.anterior_uy, 0) << "flexion closes the anterior annulus";
  EXPECT_GT(flexion.posterior_uy, 0) << "flexion opens the posterior annulus";
  EXPECT_GT(extension.anterior_uy, 0);
  EXPECT_LT(extension.posterior_uy, 0) << "extension closes the posterior annulus";

  const PlateResponse bending = respond(m, fem, "lateral-bending");
  EXPECT_GT(bending.theta.z(), 0);
  EXPECT_LT(bending.right_uy, 0) << "+Mz tips the plate towards the body's right (-x)";
  EXPECT_GT(bending.left_uy, 0);

  const PlateResponse torsion = respond(m, fem, "torsion");
  EXPECT_GT(torsion.theta.y(), 0) << "+My turns the plate anticlockwise seen from above";
  // Each moment case turns the plate mostly about its own axis.
  EXPECT_GT(std::abs(flexion.theta.x()), 3 * flexion.theta.tail<2>().norm());
  EXPECT_GT(std::abs(bending.theta.z()), 3 * bending.theta.head<2>().norm());
  EXPECT_GT(std::abs(torsion.theta.y()),
            3 * Eigen::Vector2d(torsion.theta.x(), torsion.theta.z()).norm());
}

mesh::TetMesh structured(const std::string& level, bool in_spine) {
  const auto dims = mesh::disc_dimensions(level, SPINESIM_DATA_DIR);
  return mesh::mesh_structured_disc(
      dims, {}, in_spine ? mesh::disc_frame_in_spine(level, SPINESIM_DATA_DIR) : mesh::DiscFrame());
}

}  // namespace

TEST(LoadCases, AnatomicalSignsInTheDiscFrame) { check_anatomy(structured("L4-L5", false)); }

TEST(LoadCases, AnatomicalSignsAfterTheRotationIntoTheSpine) {
  const mesh::TetMesh m = structured("L4-L5", true);
  ASSERT_GT((m.frame.axes - Eigen::Matrix3d::Identity()).norm(), 0.05)
      << "L4-L5 should be tilted in the spine";
  check_anatomy(m);
}

TEST(LoadCases, ThoracicDiscInTheSpine) { check_anatomy(structured("T7-T8", true)); }

TEST(LoadCases, GlobalWrenchIsTheLocalOneRotated) {
  const mesh::TetMesh m = structured("L1-L2", true);
  for (const auto& c : fem::standard_load_cases()) {
    const fem::Vector6d w = fem::global_wrench(c, m.frame);
    EXPECT_LE((w.head<3>() - m.frame.axes * c.wrench_local.head<3>()).norm(),
              1e-12 * c.wrench_local.norm())
        << c.name;
    EXPECT_LE((w.tail<3>() - m.frame.axes * c.wrench_local.tail<3>()).norm(),
              1e-12 * c.wrench_local.norm())
        << c.name;
  }
}
