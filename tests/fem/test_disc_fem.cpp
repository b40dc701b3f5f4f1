// DiscFem: properties of the condensed 6×6 plate stiffness and of the plate solves, and
// input validation. Meshes are structured boxes with disc-like proportions (y up).
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

mesh::TetMesh small_disc_box() {
  // 30 (x) × 8 (y) × 24 (z) mm, symmetric about x = 0.
  return spinesim::mesh::mirrored_box_mesh(3, 3, 5, 30.0, 8.0, 24.0, -9.0);
}

mesh::RegionMaterials two_regions() {
  mesh::RegionMaterials mat;
  mat.name = "test";
  mat.fallback = {4.0, 0.45, 1000.0};
  mat.by_region[2] = {1.0, 0.49, 1000.0};
  return mat;
}

// Nucleus-like inner region (label 2) that keeps the mirror symmetry.
mesh::TetMesh with_inner_region(mesh::TetMesh m) {
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += m.V.row(m.T(t, a)).transpose() / 4.0;
    if (std::abs(c.x()) < 7.5 && std::abs(c.z() - 3.0) < 6.0) m.region(t) = 2;
  }
  return m;
}

double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

Vector6d vec6(double a, double b, double c, double d, double e, double f) {
  Vector6d v;
  v << a, b, c, d, e, f;
  return v;
}

}  // namespace

class DiscFemOrder : public ::testing::TestWithParam<int> {};

TEST_P(DiscFemOrder, StiffnessIsSymmetricPositiveDefinite) {
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  const DiscFem fem(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  EXPECT_LT(fem.stiffness_asymmetry(), 1e-8);
  const Matrix6d K = fem.stiffness_6x6();
  EXPECT_EQ(K, K.transpose());
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(K);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  std::printf("P%d: %ld free DOF, K6 diag (N/mm, N·mm/rad): %s\n", GetParam(), long(fem.num_dofs()),
              [&] {
                std::ostringstream os;
                os << K.diagonal().transpose();
                return os.str();
              }()
                  .c_str());
}

TEST_P(DiscFemOrder, WrenchAndMotionSolvesAreConsistentWithK6) {
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  const DiscFem fem(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  const Matrix6d& K = fem.stiffness_6x6();
  const Vector6d w = vec6(10, -300, 25, 800, -150, 400);  // N, N·mm
  const PlateSolution sw = fem.solve_wrench(w);
  EXPECT_LT(rel(K * sw.plate_motion, w), 1e-10);
  EXPECT_LT(rel(sw.reaction_wrench, -w), 1e-8);  // the disc balances the applied wrench

  const Vector6d q = vec6(0.05, -0.2, 0.1, 0.01, -0.02, 0.005);  // mm, rad
  const PlateSolution sm = fem.solve_motion(q);
  EXPECT_EQ(sm.plate_motion, q);
  EXPECT_LT(rel(sm.reaction_wrench, -(K * q)), 1e-8);
  // Boundary values: fixed vertices do not move, plate vertices move rigidly.
  const Eigen::Vector3d c = fem.plate_center();
  for (Eigen::Index v = 0; v < m.num_vertices(); ++v) {
    if (m.surface(v) == 1) EXPECT_EQ(sm.displacement_mm.row(v).norm(), 0.0);
    if (m.surface(v) == 2) {
      const Eigen::Vector3d r = m.V.row(v).transpose() - c;
      const Eigen::Vector3d expected = q.head<3>() + q.tail<3>().cross(r);
      EXPECT_LT((sm.displacement_mm.row(v).transpose() - expected).norm(), 1e-14);
    }
  }
}

TEST_P(DiscFemOrder, ReactionMatchesDirectSumOverFullStiffness) {
  // Independent path: full K (no elimination), plate-node forces f = K u, reaction
  // = -(sum f_i, sum r_i × f_i) over the plate nodes.
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  const mesh::RegionMaterials mat = two_regions();
  const DiscFem fem(m, mat, GetParam(), DiscFem::default_plate_center(m));
  const PlateSolution s = fem.solve_motion(vec6(0.02, -0.1, 0.05, 0.01, 0.02, -0.01));
  const FeSpace space = make_fe_space(m, GetParam());
  const Eigen::VectorXi labels = node_surface_labels(space, m);
  const Eigen::SparseMatrix<double> K = assemble_stiffness(space, m.region, mat);
  ASSERT_EQ(s.node_displacement_mm.rows(), space.num_nodes());
  Eigen::VectorXd u(3 * space.num_nodes());
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i)
    u.segment<3>(3 * i) = s.node_displacement_mm.row(i).transpose();
  const Eigen::VectorXd f = K * u;
  Vector6d reaction = Vector6d::Zero();
  double free_residual = 0, scale = 0;
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    const Eigen::Vector3d fi = f.segment<3>(3 * i);
    scale = std::max(scale, fi.norm());
    if (labels(i) == 2) {
      reaction.head<3>() -= fi;
      reaction.tail<3>() -= (space.X.row(i).transpose() - fem.plate_center()).cross(fi);
    } else if (labels(i) != 1) {
      free_residual = std::max(free_residual, fi.norm());  // equilibrium at free nodes
    }
  }
  EXPECT_LT(free_residual, 1e-9 * scale);
  EXPECT_LT(rel(reaction, s.reaction_wrench), 1e-9);
}

TEST_P(DiscFemOrder, CompressionPushesBackOnThePlate) {
  const mesh::TetMesh m = small_disc_box();
  const DiscFem fem(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  const PlateSolution s = fem.solve_motion(vec6(0, -0.1, 0, 0, 0, 0));
  EXPECT_GT(s.reaction_wrench(1), 0.0);  // compressive t_y < 0 gives F_y > 0
  const PlateSolution sw = fem.solve_wrench(vec6(0, -100, 0, 0, 0, 0));  // push down with 100 N
  EXPECT_LT(sw.plate_motion(1), 0.0);
}

TEST_P(DiscFemOrder, TranslatedMeshHasTheSameStiffness) {
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  mesh::TetMesh moved = m;
  const Eigen::RowVector3d shift(120.0, -35.0, 48.0);
  moved.V.rowwise() += shift;
  const DiscFem a(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  const DiscFem b(moved, two_regions(), GetParam(), DiscFem::default_plate_center(moved));
  EXPECT_LT((b.plate_center() - a.plate_center() - shift.transpose()).norm(), 1e-12);
  EXPECT_LT(rel(b.stiffness_6x6(), a.stiffness_6x6()), 1e-9);
}

TEST_P(DiscFemOrder, StiffnessScalesLinearlyWithYoungsModulus) {
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  mesh::RegionMaterials stiff = two_regions();
  stiff.fallback.youngs_modulus_mpa *= 3.0;
  stiff.by_region[2].youngs_modulus_mpa *= 3.0;
  const DiscFem a(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  const DiscFem b(m, stiff, GetParam(), DiscFem::default_plate_center(m));
  EXPECT_LT(rel(b.stiffness_6x6(), 3.0 * a.stiffness_6x6()), 1e-10);
}

TEST_P(DiscFemOrder, MirrorSymmetryForbidsOddEvenCoupling) {
  // Reflection x -> -x maps (t, theta) to S (t, theta), S = diag(-1, 1, 1, 1, -1, -1), so
  // S K6 S = K6: entries coupling {tx, ry, rz} with {ty, tz, rx} vanish.
  const mesh::TetMesh m = with_inner_region(small_disc_box());
  const DiscFem fem(m, two_regions(), GetParam(), DiscFem::default_plate_center(m));
  EXPECT_NEAR(fem.plate_center().x(), 0.0, 1e-12);
  const Matrix6d& K = fem.stiffness_6x6();
  const int odd[3] = {0, 4, 5}, even[3] = {1, 2, 3};
  for (int i : odd)
    for (int j : even)
      EXPECT_LT(std::abs(K(i, j)), 1e-9 * std::sqrt(K(i, i) * K(j, j)))
          << "K(" << i << "," << j << ")";
  // ... while allowed couplings (e.g. tz with rx: shear with bending) are not zero.
  EXPECT_GT(std::abs(K(2, 3)), 1e-3 * std::sqrt(K(2, 2) * K(3, 3)));
}

INSTANTIATE_TEST_SUITE_P(P1AndP2, DiscFemOrder, ::testing::Values(1, 2));

TEST(DiscFem, P2NodeCountIsVerticesPlusEdges) {
  const mesh::TetMesh m = spinesim::mesh::box_mesh(2, 2, 2, 1, 1, 1);
  const DiscFem p1(m, two_regions(), 1, DiscFem::default_plate_center(m));
  const DiscFem p2(m, two_regions(), 2, DiscFem::default_plate_center(m));
  EXPECT_EQ(p1.num_nodes(), 27);
  EXPECT_EQ(p1.num_dofs(), 3 * 9);  // the middle layer
  EXPECT_EQ(p2.num_nodes(), 125);   // the Kuhn P2 nodes of a 2×2×2 grid = the 5×5×5 lattice
  EXPECT_EQ(p2.num_dofs(), 3 * (125 - 2 * 25));
}

namespace {

template <class F>
std::string invalid_argument_message(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (...) {
    return "<other exception>";
  }
  return "<no exception>";
}

}  // namespace

TEST(DiscFem, RejectsBadInputWithAClearMessage) {
  const mesh::TetMesh m = small_disc_box();
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  EXPECT_NE(invalid_argument_message([&] { DiscFem(m, two_regions(), 3, c); }).find("order"),
            std::string::npos);

  mesh::RegionMaterials bad = two_regions();
  bad.fallback.youngs_modulus_mpa = 0.0;
  const std::string msg = invalid_argument_message([&] { DiscFem(m, bad, 1, c); });
  EXPECT_NE(msg.find("region 1"), std::string::npos) << msg;

  mesh::TetMesh unlabeled = m;
  unlabeled.surface.setZero();
  EXPECT_NE(
      invalid_argument_message([&] { DiscFem(unlabeled, two_regions(), 1, c); }).find("endplate"),
      std::string::npos);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DiscFem(m, two_regions(), 1, Eigen::Vector3d(0, nan, 0)), std::invalid_argument);
  const DiscFem fem(m, two_regions(), 1, c);
  EXPECT_NE(
      invalid_argument_message([&] { fem.solve_wrench(vec6(0, nan, 0, 0, 0, 0)); }).find("wrench"),
      std::string::npos);
  EXPECT_THROW(fem.solve_motion(vec6(0, 0, 0, 0, std::numeric_limits<double>::infinity(), 0)),
               std::invalid_argument);

  mesh::TetMesh inverted = m;
  std::swap(inverted.T(0, 0), inverted.T(0, 1));
  EXPECT_THROW(DiscFem(inverted, two_regions(), 1, c), std::invalid_argument);
}

TEST(DiscFem, P2MultigridCgMatchesTheDirectSolver) {
  // A finer box so that the P1 coarse space is a real coarsening.
  mesh::TetMesh m =
      with_inner_region(spinesim::mesh::mirrored_box_mesh(4, 4, 6, 30.0, 8.0, 24.0, -9.0));
  const Eigen::Vector3d c = DiscFem::default_plate_center(m);
  SolverOptions direct, cg;
  direct.solver = LinearSolver::direct;
  cg.solver = LinearSolver::p_multigrid_cg;
  const DiscFem a(m, two_regions(), 2, c, direct);
  const DiscFem b(m, two_regions(), 2, c, cg);
  EXPECT_EQ(a.timings().cg_iterations, 0);
  EXPECT_GT(b.timings().cg_iterations, 0);
  std::printf("p-multigrid CG: %d iterations for %ld DOF\n", b.timings().cg_iterations,
              long(b.num_dofs()));
  EXPECT_LT(rel(b.stiffness_6x6(), a.stiffness_6x6()), 1e-10);
  EXPECT_LT(b.stiffness_asymmetry(), 1e-8);
  const Vector6d q = vec6(0.05, -0.2, 0.1, 0.01, -0.02, 0.005);
  const PlateSolution sa = a.solve_motion(q), sb = b.solve_motion(q);
  EXPECT_LT(rel(sb.node_displacement_mm, sa.node_displacement_mm), 1e-8);
  EXPECT_LT(rel(sb.reaction_wrench, -(b.stiffness_6x6() * q)), 1e-8);
  const Vector6d w = vec6(10, -300, 25, 800, -150, 400);
  EXPECT_LT(rel(b.solve_wrench(w).reaction_wrench, -w), 1e-8);
}
