// The nonlinear body solver (fem/hyperelastic_body.hpp) against CalculiX on the same problem: a
// fibre-reinforced block, its base held, its top moved 0.5 mm down and 0.4 mm sideways (about
// 10 % strain: fibres stretched into their toe and beyond, others slack), P1 (C3D4) and P2
// (C3D10, the same node order and the same 4-point rule). Equal displacements at every node
// and equal reactions, to CalculiX's convergence tolerance, which is set tight.
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/hyperelastic_body.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include "calculix.hpp"

#include "hyperelastic_fixtures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace spinesim::fem {
namespace {

using test::have_calculix;
using test::last_block;
using test::run_calculix;

using fixtures::annulus;

/// The base (surface 1) held, the top (surface 2) moved by `top` mm.
std::vector<PrescribedDisplacement> held_and_moved(const FeSpace& s, const Eigen::VectorXi& labels,
                                                   const Eigen::Vector3d& top) {
  std::vector<PrescribedDisplacement> bc;
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i)
    for (int d = 0; d < 3; ++d) {
      if (labels(i) == 1) bc.push_back({i, d, 0.0});
      if (labels(i) == 2) bc.push_back({i, d, top(d)});
    }
  return bc;
}

std::string deck(const FeSpace& s, const FibreHyperelastic& m,
                 const std::vector<PrescribedDisplacement>& bc) {
  std::ostringstream os;
  os << std::setprecision(13);
  os << "*NODE,NSET=NALL\n";
  for (Eigen::Index i = 0; i < s.num_nodes(); ++i)
    os << i + 1 << "," << s.X(i, 0) << "," << s.X(i, 1) << "," << s.X(i, 2) << "\n";
  os << "*ELEMENT,TYPE=" << (s.order == 1 ? "C3D4" : "C3D10") << ",ELSET=EALL\n";
  for (Eigen::Index t = 0; t < s.elements.rows(); ++t) {
    os << t + 1;
    for (int a = 0; a < s.nodes_per_element(); ++a) os << "," << s.elements(t, a) + 1;
    os << "\n";
  }
  os << test::elastic_fiber_material(m);
  os << "*SOLID SECTION,ELSET=EALL,MATERIAL=ELASTIC_FIBER\n*STEP,NLGEOM,INC=1000\n*STATIC\n"
     << "0.25,1.0\n*CONTROLS,PARAMETERS=FIELD\n1e-9,1e-9\n*BOUNDARY\n";
  for (const PrescribedDisplacement& p : bc)
    os << p.node + 1 << "," << p.dof + 1 << "," << p.dof + 1 << "," << p.value_mm << "\n";
  os << "*NODE PRINT,NSET=NALL\nU,RF\n*END STEP\n";
  return os.str();
}

class BodyAgainstCalculix : public ::testing::TestWithParam<int> {};

TEST_P(BodyAgainstCalculix, SameDisplacementsAndReactions) {
  ASSERT_TRUE(have_calculix()) << "CalculiX is the reference of this test: no " << test::kCalculix
                               << " (scripts/install-deps.sh installs calculix-ccx)";
  const int order = GetParam();
  const mesh::TetMesh box = mesh::box_mesh(3, 2, 3, 6.0, 4.0, 6.0);
  const FeSpace space = make_fe_space(box, order);
  const Eigen::VectorXi labels = node_surface_labels(space, box);
  const FibreHyperelastic m = annulus();
  const auto bc = held_and_moved(space, labels, Eigen::Vector3d(0.4, -0.5, 0.0));

  const HyperelasticBody body(space,
                              std::vector<FibreHyperelastic>(std::size_t(box.num_tets()), m));
  const HyperelasticSolution ours = body.solve(bc);
  ASSERT_TRUE(ours.converged) << ours.failure;

  const std::string dat = run_calculix("block-p" + std::to_string(order), deck(space, m, bc));
  const auto u = last_block(dat, " displacements", 1);
  const auto rf = last_block(dat, " forces", 1);
  ASSERT_EQ(Eigen::Index(u.size()), space.num_nodes()) << dat.substr(0, 2000);
  ASSERT_EQ(Eigen::Index(rf.size()), space.num_nodes());

  double worst_u = 0;
  Eigen::Vector3d top_ours = Eigen::Vector3d::Zero(), top_ccx = Eigen::Vector3d::Zero();
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    worst_u = std::max(
        worst_u,
        (ours.displacement_mm.row(i).transpose() - u[std::size_t(i)]).cwiseAbs().maxCoeff());
    if (labels(i) == 2) {
      top_ours += ours.reaction_n.row(i).transpose();
      top_ccx += rf[std::size_t(i)];
    }
  }
  std::ostringstream measured;
  measured << std::scientific << std::setprecision(2) << "max |u - u_ccx| " << worst_u
           << " mm, |R - R_ccx| / |R_ccx| " << (top_ours - top_ccx).norm() / top_ccx.norm()
           << ", |R_ccx| " << top_ccx.norm() << " N; Newton " << ours.newton_iterations
           << " iterations, " << ours.increments << " increments";
  RecordProperty("measured", measured.str());
  // Displacements printed with 7 digits of ~0.5 mm; reactions of a few N.
  EXPECT_LE(worst_u, 2e-6) << "worst nodal difference " << worst_u << " mm";
  EXPECT_LE((top_ours - top_ccx).norm(), 1e-5 * top_ccx.norm())
      << "top reaction: ours " << top_ours.transpose() << ", CalculiX " << top_ccx.transpose();
  EXPECT_GT(top_ccx.norm(), 1.0);
}

INSTANTIATE_TEST_SUITE_P(C3D4AndC3D10, BodyAgainstCalculix, ::testing::Values(1, 2));

}  // namespace
}  // namespace spinesim::fem
