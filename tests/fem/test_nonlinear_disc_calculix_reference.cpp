// The nonlinear disc reference against CalculiX on the same disc: the structured L4-L5 disc with
// the fibre-reinforced annulus (a material per tet: its two fibre directions), the inferior
// endplate held and the plate turned 6° about the disc axis while pressed 0.3 mm, as C3D4 and
// C3D10. Equal nodal displacements and an equal reaction wrench.
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/material.hpp"

#include "calculix.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace spinesim::fem {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

/// The deck: every tet its own material ELASTIC_FIBER_<t>, the plate and base nodes moved as
/// the solution says (the same prescribed values as ours).
std::string deck(const FeSpace& s, const std::vector<FibreHyperelastic>& materials,
                 const Eigen::VectorXi& labels, const Eigen::MatrixX3d& u) {
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
  os << "*STEP,NLGEOM,INC=1000\n*STATIC\n0.25,1.0\n*CONTROLS,PARAMETERS=FIELD\n1e-9,1e-9\n"
     << "*BOUNDARY\n";
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i) {
    if (labels(i) != 1 && labels(i) != 2) continue;
    for (int d = 0; d < 3; ++d) {
      const double v = std::abs(u(i, d)) < 1e-14 ? 0.0 : u(i, d);
      os << i + 1 << "," << d + 1 << "," << d + 1 << "," << v << "\n";
    }
  }
  os << "*NODE PRINT,NSET=NALL\nU,RF\n*END STEP\n";
  return os.str();
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
  const std::string dat = test::run_calculix("disc-p" + std::to_string(order),
                                             deck(s, materials, labels, ours.body.displacement_mm));
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
}

INSTANTIATE_TEST_SUITE_P(C3D4AndC3D10, DiscAgainstCalculix, ::testing::Values(1, 2));

}  // namespace
}  // namespace spinesim::fem
