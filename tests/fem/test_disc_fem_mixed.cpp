// DiscFem with the Taylor–Hood formulation and a fibre-reinforced annulus, on a structured disc.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include <cmath>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

mesh::TetMesh disc() {
  mesh::StructuredDiscOptions opt;
  opt.sectors = 16;
  opt.rings = 4;
  opt.layers = 3;
  return mesh::mesh_structured_disc({"test", 48, 34, 48, 34, 10}, opt);
}

mesh::RegionMaterials two_regions(double nucleus_nu, bool fibres) {
  mesh::RegionMaterials mat;
  mat.by_region[1] = {4.2, 0.45, 1038};
  mat.by_region[2] = {1.0, nucleus_nu, 1038};
  mat.fallback = mat.by_region[1];
  if (fibres) {
    mesh::FibreReinforcement f;
    f.modulus_inner_mpa = 59;
    f.modulus_outer_mpa = 136;
    f.angle_inner_deg = 45;
    f.angle_outer_deg = 28;
    mat.fibres[1] = f;
  }
  return mat;
}

DiscFem solve(const mesh::TetMesh& m, const mesh::RegionMaterials& mat, Formulation f) {
  SolverOptions opt;
  opt.formulation = f;
  opt.solver = LinearSolver::direct;
  return DiscFem(m, mat, 2, DiscFem::default_plate_center(m), opt);
}

TEST(DiscFemMixed, AgreesWithTheDisplacementFormWhereNeitherLocks) {
  // nu = 0.45 / 0.3: both are consistent discretisations of the same problem on the same
  // mesh; their 6x6 stiffnesses differ by the discretisation error only.
  const mesh::TetMesh m = disc();
  const mesh::RegionMaterials mat = two_regions(0.3, false);
  const Matrix6d Kd = solve(m, mat, Formulation::displacement).stiffness_6x6();
  const Matrix6d Km = solve(m, mat, Formulation::mixed).stiffness_6x6();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(Km(i, i), Kd(i, i), 0.03 * Kd(i, i)) << i;
}

TEST(DiscFemMixed, StiffnessIsSymmetricPositiveDefiniteAndReactionsBalance) {
  const mesh::TetMesh m = disc();
  const DiscFem fem = solve(m, two_regions(0.4999, true), Formulation::mixed);
  const Matrix6d K = fem.stiffness_6x6();
  EXPECT_LT(fem.stiffness_asymmetry(), 1e-8);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(K).eigenvalues().minCoeff(), 0.0);
  Vector6d w;
  w << 10, -500, 20, 300, -200, 400;
  const PlateSolution s = fem.solve_wrench(w);
  EXPECT_LT((s.reaction_wrench + w).norm(), 1e-8 * w.norm());
}

TEST(DiscFemMixed, CompressionPressurisesTheNucleusAndTorsionDoesNot) {
  const mesh::TetMesh m = disc();
  const DiscFem fem = solve(m, two_regions(0.4999, true), Formulation::mixed);
  const PlateSolution s = fem.solve_wrench(global_wrench(load_case("compression"), m.frame));
  ASSERT_EQ(s.pressure_mpa.size(), m.num_vertices());
  EXPECT_GT(s.nucleus_pressure_mpa, 0.0);
  // A pure moment about the centre neither compresses nor pressurises on average: much less
  // than the 500 N compression does.
  const PlateSolution t = fem.solve_wrench(global_wrench(load_case("torsion"), m.frame));
  EXPECT_LT(std::abs(t.nucleus_pressure_mpa), 0.05 * s.nucleus_pressure_mpa);
}

TEST(DiscFemMixed, FibresStiffenTorsionMostOfAllLoads) {
  // Fibres at 28-45 deg to the transverse plane resist the shear of axial rotation directly;
  // axial compression loads them only through the annulus bulge.
  const mesh::TetMesh m = disc();
  const Matrix6d plain = solve(m, two_regions(0.4999, false), Formulation::mixed).stiffness_6x6();
  const Matrix6d fibre = solve(m, two_regions(0.4999, true), Formulation::mixed).stiffness_6x6();
  const double torsion = fibre(4, 4) / plain(4, 4), compression = fibre(1, 1) / plain(1, 1);
  std::printf("fibres stiffen torsion x%.1f, compression x%.2f, flexion x%.2f\n", torsion,
              compression, fibre(3, 3) / plain(3, 3));
  EXPECT_GT(torsion, 5.0);
  EXPECT_GT(compression, 1.0);
  EXPECT_GT(torsion, 2.0 * compression);
}

TEST(DiscFemMixed, RefusesOrderOne) {
  const mesh::TetMesh m = disc();
  SolverOptions opt;
  opt.formulation = Formulation::mixed;
  EXPECT_THROW(DiscFem(m, two_regions(0.49, false), 1, DiscFem::default_plate_center(m), opt),
               std::invalid_argument);
}

}  // namespace
