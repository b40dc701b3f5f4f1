// Per-tet fields of the nonlinear disc (nonlinear_fields.hpp) on a disc at finite strain (Newton
// solves in four forms: seconds, so label reference), checked by identities that hold exactly for
// the discrete body, in every volumetric form and order (test_nonlinear_fields.cpp: the rest):
//   - the discrete virial theorem: Σ_t v_t σ_t = Σ_n x_n ⊗ f_n, the internal nodal forces the
//     body computes (at equilibrium, the reactions of the loaded nodes);
//   - the energy: Σ_t V₀_t W_t equals the body's energy;
//   - the pressure is −tr σ / 3 of each tet.
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

struct Form {
  const char* name;
  int order;
  VolumetricForm form;
};

const Form kForms[] = {{"P1 pointwise", 1, VolumetricForm::pointwise},
                       {"P1 nodal average", 1, VolumetricForm::nodal_average},
                       {"P2 pointwise", 2, VolumetricForm::pointwise},
                       {"P2 mean dilatation", 2, VolumetricForm::mean_dilatation}};

using fixtures::flat;
using fixtures::flexion_and_compression;

/// Σ_n x_n ⊗ f_n with f the internal forces at u and x = X + u.
Eigen::Matrix3d nodal_virial(const HyperelasticBody& body, const Eigen::VectorXd& u) {
  const HyperelasticBody::Evaluation e = body.evaluate(u, false);
  Eigen::Matrix3d out = Eigen::Matrix3d::Zero();
  for (Eigen::Index n = 0; n < body.space().num_nodes(); ++n)
    out += (body.space().X.row(n).transpose() + u.segment<3>(3 * n)) *
           e.force.segment<3>(3 * n).transpose();
  return out;
}

Eigen::Matrix3d tensor(const Eigen::RowVectorXd& s) {  // (xx, yy, zz, xy, yz, xz)
  Eigen::Matrix3d T;
  T << s(0), s(3), s(5), s(3), s(1), s(4), s(5), s(4), s(2);
  return T;
}

TEST(NonlinearFields, VirialAndEnergyIdentitiesHoldInEveryForm) {
  const mesh::TetMesh m = test::structured_test_disc(12, 3, 3);
  const mesh::RegionMaterials mat = test::fibre_annulus();
  const auto materials = disc_element_materials(m, mat, 20.0);
  for (const Form& form : kForms) {
    SCOPED_TRACE(form.name);
    const NonlinearDisc disc(m, materials, form.order, DiscFem::default_plate_center(m), form.form);
    const NonlinearPlateSolution sol = disc.solve_motion(flexion_and_compression());
    ASSERT_TRUE(sol.body.converged) << sol.body.failure;
    const Eigen::VectorXd u = flat(sol.body.displacement_mm);
    const NonlinearElementFields f = nonlinear_element_fields(disc.body(), u);
    // Σ_t v_t σ_t, v_t = J_t V₀_t.
    Eigen::Matrix3d virial = Eigen::Matrix3d::Zero();
    double energy = 0;
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
      const double V0 = mesh::tet_volume(m, t);
      virial += f.volume_ratio(t) * V0 * tensor(f.cauchy_stress_mpa.row(t));
      energy += V0 * f.strain_energy_density_mpa(t);
      EXPECT_NEAR(f.pressure_mpa(t), -tensor(f.cauchy_stress_mpa.row(t)).trace() / 3, 1e-12);
    }
    const Eigen::Matrix3d nodal = nodal_virial(disc.body(), u);
    EXPECT_LT((virial - nodal).norm(), 1e-9 * nodal.norm()) << "\n" << virial << "\n" << nodal;
    EXPECT_NEAR(energy, sol.body.energy_mj, 1e-10 * sol.body.energy_mj);
    EXPECT_GT(f.fibre_stretch.maxCoeff(), 1.01);  // the annulus's fibres are stretched
  }
}

}  // namespace
