// The linearised MSS against independent answers: the nonlinear static solver at small loads,
// the energy form of K6, and its derivative in the scales.
#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/solver.hpp"

#include "calibration_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

namespace spinesim::calibration {
namespace {

using fixtures::all_terms;
using fixtures::two_materials;
using fixtures::two_region_disc;

Eigen::VectorXd some_scales(Eigen::Index n) {
  Eigen::VectorXd s(n);
  for (Eigen::Index j = 0; j < n; ++j) s(j) = 0.6 + 0.17 * double((j * 5) % 7);
  return s;
}

TEST(LinearMss, KnobNamesRoundTrip) {
  for (const Knob& k : available_knobs(all_terms())) EXPECT_EQ(knob_from_name(knob_name(k)), k);
  EXPECT_EQ(available_knobs(all_terms()).size(), 9u);
  EXPECT_EQ(available_knobs(mss::MssOptions()).size(),
            6u);  // thesis springs: main, radial, torsion
  EXPECT_THROW(knob_from_name("torsion.cortex"), std::invalid_argument);
}

// The wrench response of the linear model is the nonlinear MSS equilibrium's first-order part:
// the static solver under eps*w, divided by eps, converges to R Z w at rate eps.
TEST(LinearMss, WrenchResponseIsTheSmallLoadLimitOfTheStaticSolver) {
  const mesh::TetMesh m = two_region_disc();
  mss::MssModel model(m, two_materials(), all_terms());
  const Eigen::Vector3d c = mss::default_plate_center(m);
  LinearMss lin(model, available_knobs(model.options()), c);
  const Eigen::VectorXd s = some_scales(9);
  std::array<mss::RegionScales, mss::kNumTerms> sc{};
  for (std::size_t j = 0; j < lin.knobs().size(); ++j)
    sc[int(lin.knobs()[j].term)].by_region[std::size_t(lin.knobs()[j].region)] = s(Eigen::Index(j));
  model.set_scales(sc);
  const LinearState st = lin.solve(s);

  Vector6d w;
  w << 30.0, -80.0, 20.0, 300.0, -200.0, 150.0;
  const Eigen::VectorXd u_lin = lin.displacement(st.Z * w);
  double previous = 0;
  for (double eps : {1e-2, 1e-3}) {
    mss::Boundary bc;
    bc.plate_mode = mss::PlateMode::wrench;
    bc.plate_center_mm = c;
    bc.wrench = eps * w;
    mss::StaticOptions so;
    so.relative_tolerance = 1e-12;
    const mss::StaticResult r = mss::solve_static(model, bc, so);
    ASSERT_TRUE(r.converged) << r.message;
    const double err = ((r.x_mm - model.rest_positions_mm()) / eps - u_lin).norm() / u_lin.norm();
    if (previous > 0) EXPECT_LT(err, 0.2 * previous);  // first order in eps
    previous = err;
  }
  EXPECT_LT(previous, 1e-3);
}

// K6 is the energy of the condensed modes: Phi^T K Phi = K6, and the plate block of Phi is I.
TEST(LinearMss, CondensedModesCarryThePlateStiffness) {
  const mesh::TetMesh m = two_region_disc();
  const mss::MssModel model(m, two_materials(), all_terms());
  LinearMss lin(model, available_knobs(model.options()), mss::default_plate_center(m));
  const Eigen::VectorXd s = some_scales(9);
  const LinearState st = lin.solve(s);
  EXPECT_LT((st.Phi.bottomRows<6>() - Matrix6d::Identity()).cwiseAbs().maxCoeff(), 1e-9);
  Matrix6d energy = Matrix6d::Zero();
  const auto grams = lin.knob_gram(st.Phi, st.Phi);
  for (std::size_t j = 0; j < grams.size(); ++j) energy += s(Eigen::Index(j)) * grams[j];
  EXPECT_LT((energy - st.k6).norm(), 1e-9 * st.k6.norm());
  EXPECT_GT(st.k6.eigenvalues().real().minCoeff(), 0.0);
}

// dK6/ds_j = Phi^T K_j Phi against central differences in s_j.
TEST(LinearMss, PlateStiffnessDerivativeMatchesFiniteDifferences) {
  const mesh::TetMesh m = two_region_disc();
  const mss::MssModel model(m, two_materials(), all_terms());
  LinearMss lin(model, available_knobs(model.options()), mss::default_plate_center(m));
  const Eigen::VectorXd s = some_scales(9);
  const LinearState st = lin.solve(s);
  const auto grams = lin.knob_gram(st.Phi, st.Phi);
  for (Eigen::Index j = 0; j < s.size(); ++j) {
    const double h = 1e-5 * s(j);
    Eigen::VectorXd sp = s, sm = s;
    sp(j) += h, sm(j) -= h;
    const Matrix6d fd = (lin.solve(sp).k6 - lin.solve(sm).k6) / (2 * h);
    EXPECT_LT((fd - grams[std::size_t(j)]).norm(), 1e-6 * st.k6.norm() / s(j))
        << knob_name(lin.knobs()[std::size_t(j)]);
  }
}

TEST(LinearMss, BadInputIsRefused) {
  const mesh::TetMesh m = two_region_disc();
  const mss::MssModel thesis(m, two_materials());
  const Eigen::Vector3d c = mss::default_plate_center(m);
  EXPECT_THROW(LinearMss(thesis, {{mss::Term::volume, 0}}, c), std::invalid_argument);  // term off
  EXPECT_THROW(LinearMss(thesis, {}, c), std::invalid_argument);
  LinearMss lin(thesis, available_knobs(thesis.options()), c);
  EXPECT_THROW(lin.solve(Eigen::VectorXd::Ones(5)), std::invalid_argument);
  Eigen::VectorXd bad = Eigen::VectorXd::Ones(6);
  bad(2) = 0.0;
  EXPECT_THROW(lin.solve(bad), std::invalid_argument);
  mesh::TetMesh no_plate = m;
  no_plate.surface.setZero();
  EXPECT_THROW(LinearMss(mss::MssModel(no_plate, two_materials()), {{mss::Term::main, 0}}, c),
               std::invalid_argument);
  // Fibre elements have no stiffness at rest: no linear response that would include them.
  mss::MssOptions fibres;
  fibres.fibre_springs = true;
  const mss::MssModel with_fibres(m, mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR),
                                  fibres);
  ASSERT_GT(with_fibres.num_fibre_springs(), 0);
  EXPECT_THROW(LinearMss(with_fibres, {{mss::Term::main, 0}}, c), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::calibration
