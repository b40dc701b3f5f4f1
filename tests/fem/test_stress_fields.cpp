// Per-tet stress, strain and energy fields (stress_fields.hpp): exact under an affine
// displacement (P1 and P2), the stress against the Voigt elasticity matrices of elasticity.hpp
// and fibres.hpp (a second route), von Mises and the principal strains against eigenvalues, and
// the energy: sum_t W_t V_t = 1/2 q^T K6 q of a plate solve in the displacement and the mixed
// form, with fibres.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/stress_fields.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include "fibre_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

mesh::RegionMaterials two_regions() {
  mesh::RegionMaterials mat;
  mat.name = "test";
  mat.fallback = {4.2, 0.45, 1038};
  mat.by_region[2] = {1.0, 0.49, 1038};
  return mat;
}

/// Every node of the order-`order` space displaced by u = G x + b.
Eigen::MatrixX3d affine(const FeSpace& s, const Eigen::Matrix3d& G, const Eigen::Vector3d& b) {
  Eigen::MatrixX3d u(s.num_nodes(), 3);
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) u.row(i) = (G * s.X.row(i).transpose() + b).transpose();
  return u;
}

/// A ParaView-ordered tensor (xx, yy, zz, xy, yz, xz) as a matrix.
Eigen::Matrix3d tensor(const Eigen::RowVectorXd& v) {
  Eigen::Matrix3d t;
  t << v(0), v(3), v(5), v(3), v(1), v(4), v(5), v(4), v(2);
  return t;
}

/// Engineering-shear Voigt vector (xx, yy, zz, yz, xz, xy) of elasticity.hpp.
Vector6d engineering(const Eigen::Matrix3d& e) {
  Vector6d v;
  v << e(0, 0), e(1, 1), e(2, 2), 2 * e(1, 2), 2 * e(0, 2), 2 * e(0, 1);
  return v;
}

Eigen::Matrix3d from_voigt(const Vector6d& s) {
  Eigen::Matrix3d t;
  t << s(0), s(5), s(4), s(5), s(1), s(3), s(4), s(3), s(2);
  return t;
}

mesh::TetMesh sample_disc() { return test::structured_test_disc(16, 4, 2); }

using test::fibre_annulus;

}  // namespace

class StressFieldsOrder : public ::testing::TestWithParam<int> {};

TEST_P(StressFieldsOrder, AffineDisplacementGivesItsStrainAndTheVoigtStressInEveryTet) {
  const int order = GetParam();
  mesh::TetMesh m = mesh::unit_cube_mesh(2);
  for (Eigen::Index t = 0; t < m.num_tets(); t += 3) m.region(t) = 2;
  // Hand-made fibres on every other tet: two directions, k = 30 MPa.
  ElementFibres fib;
  fib.direction_1.setZero(m.num_tets(), 3);
  fib.direction_2.setZero(m.num_tets(), 3);
  fib.stiffness_mpa.setZero(m.num_tets());
  const Eigen::Vector3d a1 = Eigen::Vector3d(1, 2, 0.5).normalized(), a2 = Eigen::Vector3d(-1, 2, 0.5).normalized();
  for (Eigen::Index t = 0; t < m.num_tets(); t += 2) {
    fib.direction_1.row(t) = a1.transpose();
    fib.direction_2.row(t) = a2.transpose();
    fib.stiffness_mpa(t) = 30;
  }
  Eigen::Matrix3d G;
  G << 0.010, -0.004, 0.002, 0.003, -0.020, 0.006, -0.001, 0.005, 0.007;
  const Eigen::Matrix3d eps = 0.5 * (G + G.transpose());
  const FeSpace space = make_fe_space(m, order);
  const ElementFields f =
      element_fields(m, two_regions(), fib, order, affine(space, G, Eigen::Vector3d(1, -2, 3)));
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    SCOPED_TRACE(t);
    EXPECT_LT((tensor(f.strain.row(t)) - eps).norm(), 1e-14);
    Matrix6d D = isotropic_elasticity(two_regions().at(m.region(t)));
    if (fib.stiffness_mpa(t) > 0) D += fibre_elasticity(a1, 30) + fibre_elasticity(a2, 30);
    const Eigen::Matrix3d want = from_voigt(D * engineering(eps));
    const Eigen::Matrix3d sigma = tensor(f.stress_mpa.row(t));
    EXPECT_LT((sigma - want).norm(), 1e-12 * want.norm());
    EXPECT_NEAR(f.pressure_mpa(t), -want.trace() / 3, 1e-13);
    // Von Mises from the principal stresses.
    const Eigen::Vector3d s = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(want).eigenvalues();
    EXPECT_NEAR(f.von_mises_mpa(t),
                std::sqrt(0.5 * ((s(0) - s(1)) * (s(0) - s(1)) + (s(1) - s(2)) * (s(1) - s(2)) +
                                 (s(2) - s(0)) * (s(2) - s(0)))),
                1e-12);
    // Principal strains: descending eigenpairs, orthonormal.
    Eigen::Matrix3d dirs;
    for (int k = 0; k < 3; ++k) dirs.col(k) = f.principal_strain_directions.block<1, 3>(t, 3 * k).transpose();
    EXPECT_LT((dirs.transpose() * dirs - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    for (int k = 0; k < 3; ++k)
      EXPECT_LT((eps * dirs.col(k) - f.principal_strain(t, k) * dirs.col(k)).norm(), 1e-12 * eps.norm());
    EXPECT_GE(f.principal_strain(t, 0), f.principal_strain(t, 1));
    EXPECT_GE(f.principal_strain(t, 1), f.principal_strain(t, 2));
    // Fibres: stretch and stress along each family; zero without fibres.
    const bool fibres = fib.stiffness_mpa(t) > 0;
    EXPECT_NEAR(f.fibre_stretch(t, 0), fibres ? 1 + a1.dot(eps * a1) : 0.0, 1e-15);
    EXPECT_NEAR(f.fibre_stress_mpa(t, 1), fibres ? 30 * a2.dot(eps * a2) : 0.0, 1e-12);
    // Energy density 1/2 eps : sigma for a uniform strain.
    const double w = 0.5 * (eps.array() * want.array()).sum();
    EXPECT_NEAR(f.strain_energy_density_mpa(t), w, 1e-12 * w);
  }
}

INSTANTIATE_TEST_SUITE_P(P1AndP2, StressFieldsOrder, ::testing::Values(1, 2));

TEST(StressFields, TheEnergyOfAPlateSolveIsHalfItsWorkInEveryFormulation) {
  const mesh::TetMesh m = sample_disc();
  const mesh::RegionMaterials mat = fibre_annulus();
  Vector6d q;
  q << 0.02, -0.05, 0.01, 0.004, -0.002, 0.003;  // mm, rad
  struct Case {
    int order;
    Formulation form;
  };
  for (const Case c : {Case{1, Formulation::displacement}, Case{2, Formulation::displacement},
                       Case{2, Formulation::mixed}}) {
    SCOPED_TRACE(c.order * 10 + int(c.form));
    SolverOptions opt;
    opt.formulation = c.form;
    opt.solver = LinearSolver::direct;
    const DiscFem fem(m, mat, c.order, DiscFem::default_plate_center(m), opt);
    const PlateSolution s = fem.solve_motion(q);
    const bool mixed = c.form == Formulation::mixed;
    const ElementFields f = element_fields(m, mat, fem.fibres(), c.order, s.node_displacement_mm,
                                           mixed ? &s.element_mean_stress_mpa : nullptr);
    double energy = 0;
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) energy += f.strain_energy_density_mpa(t) * mesh::tet_volume(m, t);
    const double work = 0.5 * q.dot(fem.stiffness_6x6() * q);
    EXPECT_NEAR(energy, work, 1e-9 * work);
    EXPECT_NEAR(-0.5 * q.dot(s.reaction_wrench), work, 1e-8 * work);
    // The annulus carries fibre stress, the nucleus none.
    for (Eigen::Index t = 0; t < m.num_tets(); ++t)
      if (m.region(t) == 2) EXPECT_EQ(f.fibre_stress_mpa.row(t).norm(), 0.0);
    EXPECT_GT(f.fibre_stress_mpa.cwiseAbs().maxCoeff(), 0.0);
    if (mixed) {
      // The mixed pressure field is p's negative mean in each tet, plus the fibres' share.
      Eigen::Index t = 0;
      while (m.region(t) != 2) ++t;
      EXPECT_NEAR(f.pressure_mpa(t), -s.element_mean_stress_mpa.row(t).mean(),
                  1e-12 * std::abs(f.pressure_mpa(t)) + 1e-15);
    }
  }
}

TEST(StressFields, MismatchedSizesAreRefused) {
  const mesh::TetMesh m = mesh::unit_cube_mesh(1);
  const Eigen::MatrixX3d u = Eigen::MatrixX3d::Zero(m.num_vertices(), 3);
  EXPECT_THROW(element_fields(m, two_regions(), {}, 2, u), std::invalid_argument);
  const Eigen::MatrixX4d p = Eigen::MatrixX4d::Zero(1, 4);
  EXPECT_THROW(element_fields(m, two_regions(), {}, 1, u, &p), std::invalid_argument);
  EXPECT_NO_THROW(element_fields(m, two_regions(), {}, 1, u));
}
