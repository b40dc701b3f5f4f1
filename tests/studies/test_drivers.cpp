// The study drivers called directly, as the haptic loop and the viewer will call them: the
// MSS-vs-FEM comparison against its own definitions recomputed from independent solves and the
// spine studies' invariants (the McGill
// moment reached, mirror symmetry, the number of thesis statements checked).
#include "spinesim/calibration/compare.hpp"
#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/rigid_plate.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/plate_stiffness.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/studies/calibration_summary.hpp"
#include "spinesim/studies/spine_studies.hpp"

#include "studies_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <map>

#include <cmath>

using namespace spinesim;

namespace {

using test::structured;

mesh::RegionMaterials real_disc() { return test::material("real-disc"); }

}  // namespace

TEST(ComparisonDriver, ErrorsAreTheirDefinitionsRecomputedFromIndependentSolves) {
  const mesh::TetMesh& m = structured("T7-T8");
  const auto mat = real_disc();
  const fem::DiscFem fem(m, mat, 1, fem::DiscFem::default_plate_center(m));
  const mss::MssModel model(m, mat);
  const std::vector<fem::LoadCase> cases{fem::load_case("compression"), fem::load_case("flexion")};
  const double scale = 0.3;
  const auto cmp =
      calibration::compare_mss_fem(fem, model, cases, mat.name, mss::StaticOptions(), scale);
  ASSERT_EQ(cmp.cases.size(), 2u);
  const Eigen::Vector3d c = fem.plate_center();
  for (std::size_t k = 0; k < cases.size(); ++k) {
    SCOPED_TRACE(cases[k].name);
    const auto& r = cmp.cases[k];
    const fem::Vector6d w = scale * fem::global_wrench(cases[k], m.frame);
    EXPECT_LE((r.wrench - w).norm(), 1e-12 * w.norm());
    // (a) the wrench-loaded MSS against the FEM, nodal displacements.
    const fem::PlateSolution f = fem.solve_wrench(w);
    mss::Boundary bw;
    bw.plate_mode = mss::PlateMode::wrench;
    bw.wrench = w;
    bw.plate_center_mm = c;
    const mss::StaticResult sw = mss::solve_static(model, bw);
    ASSERT_TRUE(sw.converged);
    const Eigen::MatrixX3d u = mss::displacement(model, sw.x_mm);
    EXPECT_NEAR(r.displacement_error, (u - f.displacement_mm).norm() / f.displacement_mm.norm(),
                1e-12);
    // Plate-motion error: RMS rigid displacement of the difference over that of the FEM motion.
    double num = 0, den = 0;
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
      if (m.surface(i) != int(mesh::Surface::superior_endplate)) continue;
      const Eigen::Vector3d arm = m.V.row(i).transpose() - c;
      const fem::Vector6d dq = sw.plate_motion - f.plate_motion;
      num += (dq.head<3>() + dq.tail<3>().cross(arm)).squaredNorm();
      den += (f.plate_motion.head<3>() + f.plate_motion.tail<3>().cross(arm)).squaredNorm();
    }
    EXPECT_NEAR(r.plate_motion_error, std::sqrt(num / den), 1e-12);
    // The FEM carries exactly the applied wrench: reaction = -w.
    EXPECT_LE((r.reaction_fem + w).norm(), 1e-6 * w.norm());
    EXPECT_GE(r.reaction_error, 0);
    EXPECT_LE(r.reaction_force_error, r.reaction_error + 1e-15);
    EXPECT_LE(r.reaction_moment_error, r.reaction_error + 1e-15);
  }
  // (c) K6: symmetric positive definite, the MSS one equal to mss::plate_stiffness.
  EXPECT_LE((cmp.k6_mss - mss::plate_stiffness(model, c)).norm(), 1e-12 * cmp.k6_mss.norm());
  EXPECT_LE((cmp.k6_fem - cmp.k6_fem.transpose()).norm(), 1e-9 * cmp.k6_fem.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<fem::Matrix6d>(cmp.k6_mss).eigenvalues().minCoeff(), 0);
}

TEST(ComparisonDriver, TheLinearFemScalesWithTheLoad) {
  const mesh::TetMesh& m = structured("T7-T8");
  const auto mat = real_disc();
  const fem::DiscFem fem(m, mat, 1, fem::DiscFem::default_plate_center(m));
  const mss::MssModel model(m, mat);
  const std::vector<fem::LoadCase> cases{fem::load_case("torsion")};
  const auto a =
      calibration::compare_mss_fem(fem, model, cases, mat.name, mss::StaticOptions(), 0.1);
  const auto b =
      calibration::compare_mss_fem(fem, model, cases, mat.name, mss::StaticOptions(), 0.2);
  EXPECT_LE((b.cases[0].plate_motion_fem - 2 * a.cases[0].plate_motion_fem).norm(),
            1e-10 * b.cases[0].plate_motion_fem.norm());
  EXPECT_THROW(calibration::compare_mss_fem(fem, model, cases, mat.name, mss::StaticOptions(), -1),
               std::invalid_argument);
}

TEST(SpineStudyDrivers, ValidationReachesTheMcGillMomentAndComputesTheCratePoint) {
  const studies::ValidationStudy s = studies::run_validation_study(SPINESIM_DATA_DIR);
  const auto& a = s.mcgill;
  EXPECT_GT(a.target_moment_nmm, 0);
  EXPECT_NEAR(a.external_moment_nmm, a.target_moment_nmm, 1e-3 * a.target_moment_nmm);
  EXPECT_GT(a.t7_force_n, 0);  // forward (+z) force
  EXPECT_NEAR(a.joint_moment_nmm + a.other_moment_nmm, a.external_moment_nmm,
              1e-6 * a.external_moment_nmm);
  EXPECT_GT(a.l5s1.axial_n, 0);  // compression
  const auto& b = s.wilke;
  EXPECT_GT(b.crate_point_mm.z(), 0);  // in front of the chest
  EXPECT_GT(b.l4l5.axial_n, 0);
}

TEST(SpineStudyDrivers, FusionAndTrendsAreCompleteAndSagittalLoadsStaySagittal) {
  const studies::FusionStudy f = studies::run_fusion_study(SPINESIM_DATA_DIR, 300);
  EXPECT_EQ(f.runs.size(), 12u);  // 4 models x 3 loads
  EXPECT_EQ(f.findings.size(), 21u);
  for (const char* fusion : {"normal", "L3-L4", "L4-L5", "L3-L4-L5"}) {
    SCOPED_TRACE(fusion);
    EXPECT_GT(f.run(fusion, "forward").t1_translation_mm.z(), 0);  // moves with the force
    EXPECT_LT(f.run(fusion, "backward").t1_translation_mm.z(), 0);
    EXPECT_LT(f.run(fusion, "lateral").t1_translation_mm.x(), 0);          // lateral is -x
    EXPECT_NEAR(f.run(fusion, "forward").t1_translation_mm.x(), 0, 1e-6);  // mirror-symmetric model
  }
  const studies::TrendsStudy t = studies::run_trends_study(SPINESIM_DATA_DIR, 300);
  EXPECT_EQ(t.findings.size(), 36u);
  for (const auto& r : t.runs) {
    ASSERT_EQ(r.translation_mm.rows(), 16);
    if (r.load == "lateral") continue;
    EXPECT_LE(r.translation_mm.col(0).cwiseAbs().maxCoeff(), 1e-6) << r.load;  // no lateral shear
    EXPECT_LE(r.rotation_deg.col(1).cwiseAbs().maxCoeff(), 1e-6) << r.load;    // no torsion
    EXPECT_LE(r.rotation_deg.col(2).cwiseAbs().maxCoeff(), 1e-6) << r.load;    // no lateral bending
  }
}
