// Per-tet fields of the nonlinear disc (nonlinear_fields.hpp); the virial and energy identities
// in every volumetric form are in test_nonlinear_fields_reference.cpp. Here:
//   - the small-strain limit: the Cauchy stress over the motion tends to the linear FEM's stress
//     (stress_fields.hpp) for the same small-strain moduli, the fibres aside;
//   - at rest: no stress, unit principal stretches;
//   - the principal stretches and directions are the eigenpairs of the mean C of the strain.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/fem/nonlinear_fields.hpp"
#include "spinesim/fem/stress_fields.hpp"

#include "fibre_fixtures.hpp"
#include "hyperelastic_fixtures.hpp"

#include <gtest/gtest.h>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

using fixtures::flat;
using fixtures::flexion_and_compression;

TEST(NonlinearFields, SmallStrainLimitIsTheLinearStressAndRestIsZero) {
  const mesh::TetMesh m = test::structured_test_disc(12, 3, 2);
  mesh::RegionMaterials iso = test::fibre_annulus();
  iso.fibres.clear();
  const auto materials = disc_element_materials(m, iso, 20.0);
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  const NonlinearDisc disc(m, materials, 1, c, VolumetricForm::pointwise);
  const double eps = 1e-6;
  const Eigen::Matrix<double, 6, 1> q = eps * flexion_and_compression();
  const NonlinearPlateSolution sol = disc.solve_motion(q);
  ASSERT_TRUE(sol.body.converged);
  const Eigen::VectorXd u = flat(sol.body.displacement_mm);
  const NonlinearElementFields f = nonlinear_element_fields(disc.body(), u);
  // The linear FEM's stress for the same displacements (P1: strain from the same nodes).
  const ElementFields lin = element_fields(m, iso, {}, 1, sol.body.displacement_mm);
  EXPECT_LT((f.cauchy_stress_mpa - lin.stress_mpa).norm(), 1e-4 * lin.stress_mpa.norm());
  EXPECT_LT((f.green_lagrange_strain - lin.strain).norm(), 1e-4 * lin.strain.norm());
  // At rest: no stress, unit stretches.
  const NonlinearElementFields rest =
      nonlinear_element_fields(disc.body(), Eigen::VectorXd::Zero(u.size()));
  EXPECT_LT(rest.cauchy_stress_mpa.cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((rest.principal_stretch.array() - 1).abs().maxCoeff(), 1e-12);
}

TEST(NonlinearFields, PrincipalStretchesAndDirectionsAreTheEigenpairsOfTheMeanC) {
  const mesh::TetMesh m = test::structured_test_disc(12, 3, 2);
  const auto materials = disc_element_materials(m, test::fibre_annulus(), 20.0);
  const NonlinearDisc disc(m, materials, 2, DiscFem::default_plate_center(m),
                           VolumetricForm::mean_dilatation);
  const NonlinearPlateSolution sol = disc.solve_motion(0.5 * flexion_and_compression());
  ASSERT_TRUE(sol.body.converged);
  const NonlinearElementFields f = nonlinear_element_fields(disc.body(), flat(sol.body.displacement_mm));
  double spread = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    const auto& e = f.green_lagrange_strain;  // xx yy zz xy yz xz
    Eigen::Matrix3d C;
    C << e(t, 0), e(t, 3), e(t, 5), e(t, 3), e(t, 1), e(t, 4), e(t, 5), e(t, 4), e(t, 2);
    C = Eigen::Matrix3d::Identity() + 2 * C;
    Eigen::Matrix3d axes;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d n = f.principal_stretch_directions.block<1, 3>(t, 3 * k).transpose();
      const double lambda = f.principal_stretch(t, k);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      EXPECT_LT((C * n - lambda * lambda * n).norm(), 1e-10) << t;
      Eigen::Index big = 0;
      n.cwiseAbs().maxCoeff(&big);
      EXPECT_GT(n(big), 0.0);
      axes.col(k) = n;
    }
    EXPECT_LT((axes.transpose() * axes - Eigen::Matrix3d::Identity()).norm(), 1e-10);
    EXPECT_GE(f.principal_stretch(t, 0), f.principal_stretch(t, 1));
    EXPECT_GE(f.principal_stretch(t, 1), f.principal_stretch(t, 2));
    spread = std::max(spread, f.principal_stretch(t, 0) - f.principal_stretch(t, 2));
  }
  EXPECT_GT(spread, 0.01);  // the disc is strained, the test is not about the identity
}

}  // namespace
