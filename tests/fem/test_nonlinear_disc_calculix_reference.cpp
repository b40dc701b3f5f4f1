// The nonlinear disc reference against CalculiX on the same disc: the structured L4-L5 disc with
// the fibre-reinforced annulus (a material per tet: its two fibre directions), the inferior
// endplate held and the plate turned 6° about the disc axis while pressed 0.3 mm, as C3D4 and
// C3D10. Equal nodal displacements and an equal reaction wrench; and element by element the
// fields of nonlinear_fields.hpp: each tet's Cauchy stress, von Mises stress and pressure, its
// Green–Lagrange strain, energy density and fibre stretches, rebuilt from what CalculiX prints at
// its integration points (S, the Cauchy stress; E, the Lagrange strain; ENER).
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/fem/nonlinear_fields.hpp"
#include "spinesim/fem/stress_fields.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"

#include "calculix.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <string>

namespace spinesim::fem {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

/// The deck: every tet its own material ELASTIC_FIBER_<t>, the plate and base nodes moved as
/// the solution says (the same prescribed values as ours), in fixed increments of `increment`.
std::string deck(const FeSpace& s, const std::vector<FibreHyperelastic>& materials,
                 const Eigen::VectorXi& labels, const Eigen::MatrixX3d& u, double increment) {
  std::ostringstream os;
  os << std::setprecision(13) << "*NODE,NSET=NALL\n";
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i)
    os << i + 1 << "," << s.X(i, 0) << "," << s.X(i, 1) << "," << s.X(i, 2) << "\n";
  for (Eigen::Index t = 0; t < s.elements.rows(); ++t) {
    os << "*ELEMENT,TYPE=" << (s.order == 1 ? "C3D4" : "C3D10") << ",ELSET=E" << t + 1 << "\n"
       << t + 1;
    for (int a = 0; a < s.nodes_per_element(); ++a) os << "," << s.elements(t, a) + 1;
    os << "\n"
       << test::elastic_fiber_material(materials[std::size_t(t)],
                                       "ELASTIC_FIBER_" + std::to_string(t + 1))
       << "*SOLID SECTION,ELSET=E" << t + 1 << ",MATERIAL=ELASTIC_FIBER_" << t + 1 << "\n";
  }
  os << "*ELSET,ELSET=EALL,GENERATE\n1," << s.elements.rows() << ",1\n"
     << "*STEP,NLGEOM,INC=1000\n*STATIC,DIRECT\n" << increment << ",1.0\n"
     << "*CONTROLS,PARAMETERS=FIELD\n1e-9,1e-9\n"
     << "*BOUNDARY\n";
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) {
    if (labels(i) != 1 && labels(i) != 2) continue;
    for (int d = 0; d < 3; ++d) {
      const double v = std::abs(u(i, d)) < 1e-14 ? 0.0 : u(i, d);
      os << i + 1 << "," << d + 1 << "," << d + 1 << "," << v << "\n";
    }
  }
  os << "*NODE PRINT,NSET=NALL\nU,RF\n*EL PRINT,ELSET=EALL\nS,E,ENER\n*END STEP\n";
  return os.str();
}

/// CalculiX's integration-point values as the per-tet fields of nonlinear_fields.hpp. Each
/// element's points have equal weights (1 point for C3D4, 4 for C3D10, the rules ours uses), so
/// with J_q = √det(I + 2E_q) from the printed strain: σ_t = Σ J_q σ_q / Σ J_q (the mean over the
/// deformed volume), E_t and W_t the plain means, λ_f = mean √(a·(I + 2E_q) a). Rows in our
/// order (xx, yy, zz, xy, yz, xz); CalculiX prints (xx, yy, zz, xy, xz, yz), tensor shears.
struct CalculixFields {
  Eigen::MatrixXd stress, strain, fibre_stretch;
  Eigen::VectorXd energy, von_mises, pressure;
};

Eigen::Matrix3d symmetric(const Eigen::VectorXd& v) {  // CalculiX's order
  Eigen::Matrix3d T;
  T << v(0), v(3), v(4), v(3), v(1), v(5), v(4), v(5), v(2);
  return T;
}

CalculixFields calculix_fields(const std::string& dat, Eigen::Index tets, int npts,
                               const std::vector<FibreHyperelastic>& materials) {
  const auto S = test::last_block(dat, " stresses", 2), E = test::last_block(dat, " strains", 2),
             W = test::last_block(dat, " internal energy density", 2);
  CalculixFields c;
  if (Eigen::Index(S.size()) != tets * npts || E.size() != S.size() || W.size() != S.size())
    return c;
  c.stress.resize(tets, 6);
  c.strain.resize(tets, 6);
  c.fibre_stretch = Eigen::MatrixXd::Zero(tets, 2);
  c.energy.resize(tets);
  c.von_mises.resize(tets);
  c.pressure.resize(tets);
  for (Eigen::Index t = 0; t < tets; ++t) {
    Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero(), strain = Eigen::Matrix3d::Zero();
    double v = 0, w = 0;
    for (int q = 0; q < npts; ++q) {
      const std::size_t k = std::size_t(t * npts + q);
      const Eigen::Matrix3d Eq = symmetric(E[k]);
      const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() + 2 * Eq;
      const double J = std::sqrt(C.determinant());
      sigma += J * symmetric(S[k]);
      v += J;
      strain += Eq / npts;
      w += W[k](0) / npts;
      const auto& fibres = materials[std::size_t(t)].fibres;
      for (std::size_t f = 0; f < std::min<std::size_t>(2, fibres.size()); ++f)
        c.fibre_stretch(t, Eigen::Index(f)) +=
            std::sqrt(fibres[f].direction.dot(C * fibres[f].direction)) / npts;
    }
    sigma /= v;
    const auto ours_order = [](const Eigen::Matrix3d& T) {
      Vector6d r;
      r << T(0, 0), T(1, 1), T(2, 2), T(0, 1), T(1, 2), T(0, 2);
      return r;
    };
    c.stress.row(t) = ours_order(sigma).transpose();
    c.strain.row(t) = ours_order(strain).transpose();
    c.energy(t) = w;
    c.von_mises(t) = von_mises(ours_order(sigma));
    c.pressure(t) = -sigma.trace() / 3;
  }
  return c;
}


class DiscAgainstCalculix : public ::testing::TestWithParam<int> {};

TEST_P(DiscAgainstCalculix, SameDisplacementsAndWrench) {
  ASSERT_TRUE(test::have_calculix())
      << "CalculiX is the reference of this test: no " << test::kCalculix
      << " (scripts/install-deps.sh installs calculix-ccx)";
  const int order = GetParam();
  const mesh::TetMesh m = mesh::mesh_structured_level("L4-L5", {}, SPINESIM_DATA_DIR);
  const auto materials =
      disc_element_materials(m, mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR), 10.0);
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  const NonlinearDisc d(m, materials, order, c, VolumetricForm::pointwise);
  Vector6 q = Vector6::Zero();
  q(1) = -0.3;
  q(4) = 6.0 * M_PI / 180.0;
  const NonlinearPlateSolution ours = d.solve_motion(q);
  ASSERT_TRUE(ours.body.converged) << ours.body.failure;

  const FeSpace& s = d.body().space();
  const Eigen::VectorXi labels = node_surface_labels(s, m);
  // Twice, in 10 and in 20 increments: CalculiX sums the energy density over the increments
  // (second order in the increment: 4 increments left it 1–2 % off, 20 increments 25–35 times
  // less), so the energy is compared by Richardson's extrapolation of the two.
  const std::string name = "disc-p" + std::to_string(order);
  const std::string coarse =
      test::run_calculix(name + "-10", deck(s, materials, labels, ours.body.displacement_mm, 0.1));
  const std::string dat =
      test::run_calculix(name + "-20", deck(s, materials, labels, ours.body.displacement_mm, 0.05));
  const auto u = test::last_block(dat, " displacements", 1);
  const auto rf = test::last_block(dat, " forces", 1);
  ASSERT_EQ(Eigen::Index(u.size()), s.num_nodes());
  ASSERT_EQ(Eigen::Index(rf.size()), s.num_nodes());
  double worst = 0;
  Eigen::Vector3d F = Eigen::Vector3d::Zero(), M = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) {
    worst = std::max(
        worst,
        (ours.body.displacement_mm.row(i).transpose() - u[std::size_t(i)]).cwiseAbs().maxCoeff());
    if (labels(i) != 2) continue;
    const Eigen::Vector3d x = s.X.row(i).transpose() + u[std::size_t(i)];
    F -= rf[std::size_t(i)];
    M -= (x - c - q.head<3>()).cross(Eigen::Vector3d(rf[std::size_t(i)]));
  }
  std::ostringstream measured;
  measured << std::scientific << std::setprecision(2) << "max |u - u_ccx| " << worst << " mm; F "
           << ours.reaction_wrench.head<3>().transpose() << " vs " << F.transpose() << " N; M "
           << ours.reaction_wrench.tail<3>().transpose() << " vs " << M.transpose()
           << " N·mm; Newton " << ours.body.newton_iterations << " iterations, "
           << ours.body.increments << " increments, " << ours.body.seconds << " s";
  RecordProperty("measured", measured.str());
  EXPECT_LE(worst, 1e-5) << measured.str();
  EXPECT_LE((ours.reaction_wrench.head<3>() - F).norm(), 1e-5 * F.norm()) << measured.str();
  EXPECT_LE((ours.reaction_wrench.tail<3>() - M).norm(), 1e-5 * M.norm()) << measured.str();

  // The fields, element by element.
  Eigen::VectorXd u_flat(3 * s.num_nodes());
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i)
    u_flat.segment<3>(3 * i) = ours.body.displacement_mm.row(i).transpose();
  const NonlinearElementFields f = nonlinear_element_fields(d.body(), u_flat);
  const int npts = order == 1 ? 1 : 4;
  const CalculixFields ccx = calculix_fields(dat, m.num_tets(), npts, materials),
                       ccx_coarse = calculix_fields(coarse, m.num_tets(), npts, materials);
  ASSERT_EQ(ccx.stress.rows(), m.num_tets()) << "CalculiX printed no fields for every element";
  ASSERT_EQ(ccx_coarse.stress.rows(), m.num_tets());
  const Eigen::VectorXd energy = (4 * ccx.energy - ccx_coarse.energy) / 3;
  const double es = test::relative_difference(f.cauchy_stress_mpa, ccx.stress),
               evm = test::relative_difference(f.von_mises_mpa, ccx.von_mises),
               ep = test::relative_difference(f.pressure_mpa, ccx.pressure),
               ee = test::relative_difference(f.green_lagrange_strain, ccx.strain),
               ew20 = test::relative_difference(f.strain_energy_density_mpa, ccx.energy),
               ew = test::relative_difference(f.strain_energy_density_mpa, energy),
               el = (f.fibre_stretch - ccx.fibre_stretch).cwiseAbs().maxCoeff();
  std::ostringstream fields;
  fields << std::scientific << std::setprecision(1) << "| C3D" << (order == 1 ? 4 : 10) << " | "
         << m.num_tets() << " | " << es << " | " << evm << " | " << ep << " | " << ee << " | "
         << ew << " (" << ew20 << " unextrapolated) | " << el << " | max von Mises " << f.von_mises_mpa.maxCoeff()
         << " MPa, fibre stretch " << f.fibre_stretch.maxCoeff() << " |";
  RecordProperty("fields", fields.str());
  std::printf("| element | tets | stress | von Mises | pressure | strain | energy density | "
              "fibre stretch (abs) | |\n%s\n",
              fields.str().c_str());
  // CalculiX prints 7 significant digits: agreement to its print precision.
  EXPECT_LT(es, 1e-5) << fields.str();
  EXPECT_LT(evm, 1e-5) << fields.str();
  EXPECT_LT(ep, 1e-5) << fields.str();
  EXPECT_LT(ee, 1e-5) << fields.str();
  EXPECT_LT(ew, 1e-5) << fields.str();
  EXPECT_LT(el, 1e-5) << fields.str();
  EXPECT_GT(f.fibre_stretch.maxCoeff(), 1.01);  // the fibres are loaded
  EXPECT_LT(ew, 0.1 * ew20) << "the extrapolation did not converge on our energy";
}

INSTANTIATE_TEST_SUITE_P(C3D4AndC3D10, DiscAgainstCalculix, ::testing::Values(1, 2));

}  // namespace
}  // namespace spinesim::fem
