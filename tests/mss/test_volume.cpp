// Volume under 10 % axial compression : the thesis claims its radial springs
// (5.3)-(5.5) preserve volume but never measured it. Variants of the same L4-L5 disc, real-disc
// material (E 3.22 MPa, nu 0.4557), superior plate pushed down by 10 % of the equivalent-cylinder
// height (static equilibrium, inferior endplate fixed):
//   springs only        main + torsion
//   thesis              main + torsion + radial                  (the thesis model)
//   per-tet volume      + 1/2 k_v (V_t - V0_t)^2, k_v = K/V0_t    (beyond the thesis)
//   whole-disc volume   + 1/2 k_g (V - V0)^2,    k_g = 10 K/V0 (the default c_g; beyond the thesis)
// and, as the physical reference, the P2 FEM on the same mesh (volume of the deformed vertices).
// Measured (this test prints them): -9.3 %, -9.0 %, -4.9 %, -0.69 %; FEM -4.7 %. The radial
// springs do not preserve volume; the per-tet term at the material's bulk modulus reproduces
// the FEM's volume change (a homogeneous nu = 0.456 solid is not incompressible), and only the
// whole-disc term meets the issue's < 1 % — the per-tet term cannot (it locks: c_v = 100 still
// loses 1.2 % at 24x the FEM's force).
#include "solver_fixtures.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace spinesim::mss {
namespace {

struct Variant {
  const char* name;
  bool radial, volume, disc_volume;
};

struct Outcome {
  double volume_change, reaction_n;
};

const mesh::TetMesh& disc() { return fixtures::l4_l5(3.0); }

double ten_percent_mm() {
  return 0.1 * MssModel(disc(), fixtures::real_disc()).cylinder().length_mm;
}

Outcome compress(const Variant& v) {
  MssOptions o;
  o.radial_springs = v.radial;
  o.volume_term = v.volume;
  o.disc_volume_term = v.disc_volume;
  const MssModel model(disc(), fixtures::real_disc(), o);
  const StaticResult r = solve_static(
      model, fixtures::motion_boundary(disc(), fixtures::vec6(0, -ten_percent_mm(), 0, 0, 0, 0)));
  EXPECT_TRUE(r.converged) << v.name << ": " << r.message;
  return {model.volume_mm3(r.x_mm) / model.rest_volume_mm3() - 1.0, r.reaction_wrench(1)};
}

TEST(MssVolume, TenPercentCompression) {
  const Variant variants[] = {{"springs only", false, false, false},
                              {"thesis radial springs", true, false, false},
                              {"per-tet volume term", true, true, false},
                              {"whole-disc volume term", true, false, true}};
  Outcome out[4];
  for (int i = 0; i < 4; ++i) {
    out[i] = compress(variants[i]);
    std::printf("[ volume   ] %-24s dV/V = %+.3f %%   reaction Fy = %7.1f N\n", variants[i].name,
                100.0 * out[i].volume_change, out[i].reaction_n);
    RecordProperty(std::string("volume_change_percent_") + std::to_string(i),
                   std::to_string(100.0 * out[i].volume_change));
  }
  // FEM reference on the same mesh: the disc material's own volume change.
  const fem::DiscFem fem(disc(), fixtures::real_disc(), 2,
                         fem::DiscFem::default_plate_center(disc()));
  fem::Vector6d q = fem::Vector6d::Zero();
  q(1) = -ten_percent_mm();
  const fem::PlateSolution s = fem.solve_motion(q);
  mesh::TetMesh deformed = disc();
  deformed.V += s.displacement_mm;
  const double fem_change = mesh::mesh_volume(deformed) / mesh::mesh_volume(disc()) - 1.0;
  std::printf("[ volume   ] %-24s dV/V = %+.3f %%   reaction Fy = %7.1f N\n", "FEM P2 (reference)",
              100.0 * fem_change, s.reaction_wrench(1));

  for (int i = 0; i < 4; ++i) {
    EXPECT_LT(out[i].volume_change, 0.0) << variants[i].name;  // compression loses volume
    EXPECT_GT(out[i].reaction_n, 0.0) << variants[i].name;     // and pushes back on the plate
  }
  // The thesis's radial springs change little: within 1 point of the springs-only network.
  EXPECT_LT(std::abs(out[1].volume_change - out[0].volume_change), 0.01);
  // The per-tet term at the bulk modulus reproduces the FEM's volume change to 1 point.
  EXPECT_LT(std::abs(out[2].volume_change - fem_change), 0.01);
  // The target: the whole-disc volume term keeps |dV/V| under 1 %.
  EXPECT_LT(std::abs(out[3].volume_change), 0.01);
}

}  // namespace
}  // namespace spinesim::mss

namespace spinesim::mss {
namespace {

// The per-tet spring strain: a uniform stretch by s gives s on every tet, a rigid motion 0, and
// the largest-magnitude edge wins with its sign (brute force over the six edges).
TEST(MssQuantities, EdgeStrainIsTheLargestEdgeStrainPerTet) {
  const MssModel model(fixtures::small_box(), fixtures::real_disc());
  const Eigen::VectorXd X = model.rest_positions_mm();
  const Eigen::Index n = model.num_nodes();
  Eigen::VectorXd x = X * 1.03;
  EXPECT_LT((tet_edge_strain(model, x).array() - 0.03).abs().maxCoeff(), 1e-12);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (Eigen::Index i = 0; i < n; ++i)
    x.segment<3>(3 * i) = R * X.segment<3>(3 * i) + Eigen::Vector3d(5, -2, 1);
  EXPECT_LT(tet_edge_strain(model, x).cwiseAbs().maxCoeff(), 1e-12);
  x = X;
  for (Eigen::Index i = 0; i < n; ++i) x(3 * i + 1) *= 0.9 + 0.05 * std::sin(double(i));
  const Eigen::VectorXd e = tet_edge_strain(model, x);
  const mesh::TetMesh& m = model.mesh();
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    double want = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const Eigen::Index i = m.T(t, a), j = m.T(t, b);
        const double s = (x.segment<3>(3 * j) - x.segment<3>(3 * i)).norm() /
                             (X.segment<3>(3 * j) - X.segment<3>(3 * i)).norm() -
                         1;
        if (std::abs(s) > std::abs(want)) want = s;
      }
    EXPECT_NEAR(e(t), want, 1e-14) << "tet " << t;
  }
}

}  // namespace
}  // namespace spinesim::mss
