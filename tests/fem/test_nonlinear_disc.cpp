// The nonlinear disc reference (fem/nonlinear_disc.hpp): at small plate motions its reaction is
// the linear FEM's −K6 q (the gap first order in the motion), a fibre-reinforced disc turned
// 5° resists the turn and converges, and the element materials follow the fibre field.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fibres.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace spinesim::fem {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

mesh::TetMesh disc() { return mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR); }

class SmallMotion : public ::testing::TestWithParam<int> {};

TEST_P(SmallMotion, TheReactionIsTheLinearFemsAtSmallMotions) {
  const int order = GetParam();
  const mesh::TetMesh m = disc();
  const mesh::RegionMaterials mat = mesh::load_material("real-disc", SPINESIM_DATA_DIR);
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  const DiscFem linear(m, mat, order, c);
  const NonlinearDisc nonlinear(m, disc_element_materials(m, mat, 0.0), order, c);
  const Vector6 q = (Vector6() << 0.02, -0.05, 0.01, 0.004, -0.003, 0.002).finished();
  double gaps[2];
  for (int k = 0; k < 2; ++k) {
    const Vector6 qk = q * (k == 0 ? 1.0 : 0.1);
    const NonlinearPlateSolution s = nonlinear.solve_motion(qk);
    ASSERT_TRUE(s.body.converged) << s.body.failure;
    const Vector6 expected = -linear.stiffness_6x6() * qk;
    // Forces and moments compared in one unit: moments over the plate's radius (about 20 mm).
    Vector6 w = (s.reaction_wrench - expected).cwiseAbs();
    w.tail<3>() /= 20.0;
    Vector6 e = expected.cwiseAbs();
    e.tail<3>() /= 20.0;
    gaps[k] = w.norm() / e.norm();
  }
  EXPECT_LT(gaps[0], 0.05) << "relative gap " << gaps[0];
  EXPECT_NEAR(gaps[1] / gaps[0], 0.1, 0.03) << gaps[0] << " then " << gaps[1];
}

INSTANTIATE_TEST_SUITE_P(P1AndP2, SmallMotion, ::testing::Values(1, 2));

TEST(NonlinearDisc, AFibreDiscTurnedFiveDegreesResistsTheTurn) {
  const mesh::TetMesh m = disc();
  const mesh::RegionMaterials mat = mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
  const auto materials = disc_element_materials(m, mat, 10.0);
  int with_fibres = 0;
  for (const auto& h : materials) with_fibres += h.fibres.empty() ? 0 : 1;
  EXPECT_GT(with_fibres, 0);
  EXPECT_LT(with_fibres, m.num_tets());  // the nucleus has none
  const NonlinearDisc d(m, materials, 1, DiscFem::default_plate_center(m));
  Vector6 q = Vector6::Zero();
  q(4) = 5.0 * M_PI / 180.0;  // axial torsion about y
  const NonlinearPlateSolution s = d.solve_motion(q);
  ASSERT_TRUE(s.body.converged) << s.body.failure;
  EXPECT_LT(s.reaction_wrench(4), 0);  // the disc turns the plate back
  EXPECT_TRUE(s.reaction_wrench.allFinite());
  // Twice the turn, more than twice the moment: the fibres stiffen.
  const NonlinearPlateSolution s2 = d.solve_motion(2 * q);
  ASSERT_TRUE(s2.body.converged) << s2.body.failure;
  EXPECT_LT(s2.reaction_wrench(4), 2 * s.reaction_wrench(4));
}

}  // namespace
}  // namespace spinesim::fem
