// Static equilibrium of the MSS disc (solver.hpp, solve_static): small-load linearity against
// the linear solve with the rest stiffness and its condensed 6x6 plate stiffness K6, wrench- and
// pose-mode consistency, rigid motions, force and moment balance with probes and nodal forces,
// large compression, and bad input.
#include "spinesim/mss/solver.hpp"

#include "solver_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/SparseCholesky>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

namespace spinesim::mss {
namespace {

using fixtures::vec6;

mesh::RegionMaterials soft_and_softer() {
  mesh::RegionMaterials m;
  m.name = "test";
  m.fallback = {4.2, 0.45, 1038.0};
  m.by_region[2] = {1.0, 0.49, 1038.0};
  return m;
}

/// The disc box with a nucleus-like inner region (label 2).
mesh::TetMesh two_region_box() {
  mesh::TetMesh m = fixtures::small_box();
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += 0.25 * m.V.row(m.T(t, k)).transpose();
    if (std::abs(c.x()) < 5.0 && std::abs(c.z()) < 4.0) m.region(t) = 2;
  }
  return m;
}

Eigen::Matrix<double, 3, 6> plate_map(const Eigen::Vector3d& r) {
  Eigen::Matrix<double, 3, 6> R;
  R << 1, 0, 0, 0, r.z(), -r.y(), 0, 1, 0, -r.z(), 0, r.x(), 0, 0, 1, r.y(), -r.x(), 0;
  return R;
}

/// The linear problem of the rest stiffness K (the model's Hessian at rest), built independently
/// of the solver: free DOF f, plate DOF q through the FEM map, fixed DOF zero.
///   u_f(q) = -K_ff^-1 K_fp q,   K6 = K_pp - K_fp^T K_ff^-1 K_fp,   reaction = -K6 q.
struct LinearReference {
  std::vector<int> free_dof;  ///< full DOF index of each free unknown
  Eigen::MatrixXd Kfp;        ///< #free x 6
  Matrix6d K6;
  Eigen::MatrixXd Z;  ///< K_ff^-1 K_fp
  Eigen::Vector3d c;
  const mesh::TetMesh* m;

  LinearReference(const MssModel& model, const Eigen::Vector3d& center)
      : c(center), m(&model.mesh()) {
    Eigen::SparseMatrix<double> K;
    model.hessian(model.rest_positions_mm(), HessianMode::exact, K);
    const Eigen::Index n = model.num_nodes();
    std::vector<int> index(std::size_t(3 * n), -1);
    for (Eigen::Index i = 0; i < n; ++i)
      if (m->surface(i) != 1 && m->surface(i) != 2)
        for (int d = 0; d < 3; ++d) {
          index[std::size_t(3 * i + d)] = int(free_dof.size());
          free_dof.push_back(int(3 * i + d));
        }
    // Plate columns: K(:, plate) R.
    Eigen::MatrixXd Kall_p = Eigen::MatrixXd::Zero(3 * n, 6);
    for (Eigen::Index j = 0; j < n; ++j)
      if (m->surface(j) == 2) {
        const auto R = plate_map(model.rest_positions_mm().segment<3>(3 * j) - c);
        Kall_p += K.middleCols(3 * j, 3) * R;
      }
    K6.setZero();
    for (Eigen::Index i = 0; i < n; ++i)
      if (m->surface(i) == 2)
        K6 += plate_map(model.rest_positions_mm().segment<3>(3 * i) - c).transpose() *
              Kall_p.middleRows(3 * i, 3);
    std::vector<Eigen::Triplet<double>> trip;
    for (int col = 0; col < K.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
        if (index[std::size_t(it.row())] >= 0 && index[std::size_t(col)] >= 0)
          trip.emplace_back(index[std::size_t(it.row())], index[std::size_t(col)], it.value());
    const Eigen::Index nf = Eigen::Index(free_dof.size());
    Eigen::SparseMatrix<double> Kff(nf, nf);
    Kff.setFromTriplets(trip.begin(), trip.end());
    Kfp.resize(nf, 6);
    for (Eigen::Index k = 0; k < nf; ++k) Kfp.row(k) = Kall_p.row(free_dof[std::size_t(k)]);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(Kff);
    EXPECT_EQ(ldlt.info(), Eigen::Success);
    Z = ldlt.solve(Kfp);
    K6 -= Kfp.transpose() * Z;
  }

  /// Displacement field (3#nodes) of the linear solve for plate motion q.
  Eigen::VectorXd displacement(const MssModel& model, const Vector6d& q) const {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(model.num_dofs());
    const Eigen::VectorXd uf = -Z * q;
    for (std::size_t k = 0; k < free_dof.size(); ++k) u(free_dof[k]) = uf(Eigen::Index(k));
    for (Eigen::Index i = 0; i < model.num_nodes(); ++i)
      if (m->surface(i) == 2)
        u.segment<3>(3 * i) = plate_map(model.rest_positions_mm().segment<3>(3 * i) - c) * q;
    return u;
  }
};

double rel(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

// Wrench components in N and N·mm: compare them as forces with the moments over the plate size.
Vector6d as_forces(Vector6d w, double length_mm) {
  w.tail<3>() /= length_mm;
  return w;
}

class SolverBox : public ::testing::Test {
 protected:
  SolverBox()
      : mesh_(two_region_box()),
        model_(mesh_, soft_and_softer()),
        c_(default_plate_center(mesh_)) {}
  mesh::TetMesh mesh_;
  MssModel model_;
  Eigen::Vector3d c_;
  const Vector6d q_hat_ = vec6(0.02, -0.05, 0.01, 0.002, -0.003, 0.001);  // mm, rad
};

TEST_F(SolverBox, UnloadedDiscStaysAtRest) {
  const StaticResult r = solve_static(model_, fixtures::motion_boundary(mesh_, Vector6d::Zero()));
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.iterations, 0);
  EXPECT_LT((r.x_mm - model_.rest_positions_mm()).norm(), 1e-12);
  EXPECT_LT(r.reaction_wrench.norm(), 1e-10);
}

// Contact is a surface effect: a probe around an interior node (surface label 0) touches
// nothing, while the same probe around a wall node pushes it out.
TEST_F(SolverBox, ProbesTouchOnlySurfaceNodes) {
  auto probe_at = [&](int label) {
    Eigen::Index node = 0;
    while (mesh_.surface(node) != label) ++node;
    Boundary bc = fixtures::motion_boundary(mesh_, Vector6d::Zero());
    const Eigen::Vector3d X = model_.rest_positions_mm().segment<3>(3 * node);
    bc.probes.push_back({X + Eigen::Vector3d(0.05, 0.05, 0.05), 0.5, 0.0});
    const StaticResult r = solve_static(model_, bc);
    EXPECT_TRUE(r.converged) << r.message;
    return std::make_pair((r.x_mm - model_.rest_positions_mm()).norm(),
                          probe_forces(model_, bc, r.x_mm)[0].norm());
  };
  const auto interior = probe_at(0), wall = probe_at(3);
  EXPECT_EQ(interior.first, 0.0);
  EXPECT_EQ(interior.second, 0.0);
  EXPECT_GT(wall.first, 1e-3);
  EXPECT_GT(wall.second, 0.0);
}

TEST_F(SolverBox, SmallMotionEqualsTheLinearSolveToSecondOrder) {
  const LinearReference lin(model_, c_);
  double previous = 0;
  for (double eps : {1e-2, 1e-3}) {
    const Vector6d q = eps * q_hat_;
    const StaticResult r = solve_static(model_, fixtures::motion_boundary(mesh_, q));
    ASSERT_TRUE(r.converged) << r.message;
    const Eigen::VectorXd u = r.x_mm - model_.rest_positions_mm();
    const Eigen::VectorXd u_lin = lin.displacement(model_, q);
    const double err = (u - u_lin).norm();
    std::printf("eps %g: |u| = %.3e mm, |u - u_lin| / |u| = %.3e, %d Newton iterations\n", eps,
                u.norm(), err / u.norm(), r.iterations);
    EXPECT_LT(err / u_lin.norm(), 10 * eps);
    if (previous > 0) {  // the error is quadratic in the load: x10 smaller load, x100 smaller error
      EXPECT_GT(previous / err, 50.0);
      EXPECT_LT(previous / err, 200.0);
    }
    previous = err;
  }
}

TEST_F(SolverBox, SmallMotionReactionIsMinusCondensedStiffnessTimesMotion) {
  const LinearReference lin(model_, c_);
  const double L = 10.0;  // mm, plate half-size: moments compared as forces
  EXPECT_LT((lin.K6 - lin.K6.transpose()).norm(), 1e-10 * lin.K6.norm());
  double previous = 0;
  Vector6d first;
  for (double eps : {1e-2, 1e-3}) {
    const Vector6d q = eps * q_hat_;
    const StaticResult r = solve_static(model_, fixtures::motion_boundary(mesh_, q));
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LT((r.plate_motion - q).norm(), 1e-15);
    const Vector6d expected = -lin.K6 * q;
    const double err =
        (as_forces(r.reaction_wrench - expected, L)).norm() / as_forces(expected, L).norm();
    EXPECT_LT(err, 10 * eps);
    if (previous > 0) {
      EXPECT_GT(previous / err, 5.0);  // linear in the load: the relative error shrinks with it
      // Reaction scales linearly: R(q) / eps is the same to O(eps).
      EXPECT_LT(as_forces(first / 1e-2 - r.reaction_wrench / 1e-3, L).norm(),
                0.05 * as_forces(first / 1e-2, L).norm());
    } else {
      first = r.reaction_wrench;
    }
    previous = err;
  }
  // A compressive motion pushes the plate up: F_y > 0.
  const StaticResult down =
      solve_static(model_, fixtures::motion_boundary(mesh_, vec6(0, -0.01, 0, 0, 0, 0)));
  EXPECT_GT(down.reaction_wrench(1), 0.0);
}

TEST_F(SolverBox, WrenchAndPoseModesAgree) {
  const double L = 10.0;
  for (double scale : {1.0, 0.1}) {
    const Vector6d w = scale * vec6(0.2, -1.0, 0.3, 2.0, -1.5, 1.0);  // N, N·mm
    const StaticResult rw = solve_static(model_, fixtures::wrench_boundary(mesh_, w));
    ASSERT_TRUE(rw.converged) << rw.message;
    // The disc balances the applied wrench: reaction = -w up to the moved centre (second order).
    const double ew = as_forces(rw.reaction_wrench + w, L).norm() / as_forces(w, L).norm();
    // The same plate motion prescribed as a pose gives back the wrench.
    const StaticResult rp = solve_static(model_, fixtures::motion_boundary(mesh_, rw.plate_motion));
    ASSERT_TRUE(rp.converged) << rp.message;
    const double ep = as_forces(rp.reaction_wrench + w, L).norm() / as_forces(w, L).norm();
    const double ex = (rp.x_mm - rw.x_mm).norm() / (rw.x_mm - model_.rest_positions_mm()).norm();
    std::printf(
        "wrench x%g: |q| = %.2e, rel. reaction error wrench mode %.2e, pose mode %.2e, "
        "positions %.2e\n",
        scale, rw.plate_motion.norm(), ew, ep, ex);
    EXPECT_LT(ew, 1e-2 * scale);
    EXPECT_LT(ep, 1e-2 * scale);
    EXPECT_LT(ex, 1e-2 * scale);
  }
}

TEST_F(SolverBox, RigidMotionOfBothEndplatesIsStressFree) {
  Boundary bc;
  bc.plate_center_mm = c_;
  bc.inferior = plate_pose(vec6(2.0, -1.0, 3.0, 0.2, -0.3, 0.1), Eigen::Vector3d(0.0, 4.0, 0.0));
  bc.superior = bc.inferior;
  const StaticResult r = solve_static(model_, bc);
  ASSERT_TRUE(r.converged) << r.message;
  Eigen::VectorXd expected(model_.num_dofs());
  for (Eigen::Index i = 0; i < model_.num_nodes(); ++i)
    expected.segment<3>(3 * i) = bc.inferior.apply(model_.rest_positions_mm().segment<3>(3 * i));
  std::printf("rigid motion: %d Newton iterations, max |x - P(X)| = %.2e mm, E = %.2e N·mm\n",
              r.iterations, (r.x_mm - expected).cwiseAbs().maxCoeff(), model_.energy(r.x_mm));
  EXPECT_LT((r.x_mm - expected).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(model_.energy(r.x_mm), 1e-20);
  EXPECT_LT(r.reaction_wrench.norm(), 1e-9);
}

TEST_F(SolverBox, EquilibriumBalancesPlateFixedEndplateProbeAndNodalForces) {
  Boundary bc = fixtures::motion_boundary(mesh_, vec6(0.05, -0.3, 0.02, 0.01, 0.0, -0.01));
  // A probe pressed 0.5 mm into the right wall, and nodal forces on two interior nodes.
  const Probe probe{Eigen::Vector3d(11.5, 8.0 / 3.0, 0.0), 2.0, 200.0};
  bc.probes.push_back(probe);
  bc.nodal_forces_n = Eigen::VectorXd::Zero(model_.num_dofs());
  std::vector<int> interior;
  for (Eigen::Index i = 0; i < model_.num_nodes(); ++i)
    if (mesh_.surface(i) == 0) interior.push_back(int(i));
  ASSERT_GE(interior.size(), 2u);
  bc.nodal_forces_n.segment<3>(3 * interior.front()) = Eigen::Vector3d(0.5, 0.2, -0.3);
  bc.nodal_forces_n.segment<3>(3 * interior.back()) = Eigen::Vector3d(-0.1, 0.4, 0.2);
  StaticOptions tight;  // equilibrium to round-off, node by node
  tight.relative_tolerance = 1e-12;
  const StaticResult r = solve_static(model_, bc, tight);
  ASSERT_TRUE(r.converged) << r.message;
  std::printf("equilibrium with probe and nodal forces: %d Newton iterations to |r| = %.2e N\n",
              r.iterations, r.residual_n);

  Eigen::VectorXd g;
  model_.gradient(r.x_mm, g);
  const std::vector<Eigen::Vector3d> fp = probe_forces(model_, bc, r.x_mm);
  ASSERT_EQ(fp.size(), 1u);
  EXPECT_GT(fp[0].norm(), 0.0) << "the probe must touch the disc";
  // The reduced gradient vanishes: on every free node dE/dx + d(contact)/dx - f = 0.
  double worst = 0, gmax = 0;
  for (Eigen::Index i = 0; i < model_.num_nodes(); ++i) {
    gmax = std::max(gmax, g.segment<3>(3 * i).norm());
    if (mesh_.surface(i) == 1 || mesh_.surface(i) == 2) continue;
    Eigen::Vector3d gp;
    probe_contact(r.x_mm.segment<3>(3 * i), probe.center_mm, probe.radius_mm,
                  probe.stiffness_n_per_mm, &gp);
    worst =
        std::max(worst, (g.segment<3>(3 * i) + gp - bc.nodal_forces_n.segment<3>(3 * i)).norm());
  }
  EXPECT_LT(worst, 1e-9 * gmax);
  EXPECT_LT(r.residual_n, 1e-8 * gmax);
  Eigen::Vector3d F_plate = Eigen::Vector3d::Zero(), F_inf = Eigen::Vector3d::Zero(),
                  F_free = Eigen::Vector3d::Zero(), M_all = Eigen::Vector3d::Zero();
  double scale = 0;
  for (Eigen::Index i = 0; i < model_.num_nodes(); ++i) {
    const Eigen::Vector3d gi = g.segment<3>(3 * i);
    scale += gi.norm();
    M_all += r.x_mm.segment<3>(3 * i).cross(gi);
    if (mesh_.surface(i) == 2)
      F_plate -= gi;
    else if (mesh_.surface(i) == 1)
      F_inf -= gi;
    else
      F_free += gi;
  }
  const Eigen::Vector3d F_nodal = bc.nodal_forces_n.reshaped(3, model_.num_nodes()).rowwise().sum();
  std::printf(
      "balance: F_plate %s, F_inferior %s, F_probe %s, F_nodal %s (N)\n",
      [&] {
        std::ostringstream o;
        o << F_plate.transpose();
        return o.str();
      }()
          .c_str(),
      [&] {
        std::ostringstream o;
        o << F_inf.transpose();
        return o.str();
      }()
          .c_str(),
      [&] {
        std::ostringstream o;
        o << fp[0].transpose();
        return o.str();
      }()
          .c_str(),
      [&] {
        std::ostringstream o;
        o << F_nodal.transpose();
        return o.str();
      }()
          .c_str());
  // Internal forces: zero net force and moment.
  EXPECT_LT(M_all.norm(), 1e-10 * scale * 20.0);
  // The plate reaction reported is the same sum.
  EXPECT_LT((r.reaction_wrench.head<3>() - F_plate).norm(), 1e-12 * scale);
  // Free nodes: sum of dE/dx = f_nodal - (contact forces on the nodes) = f_nodal - F_probe.
  EXPECT_LT((F_free - (F_nodal - fp[0])).norm(), 1e-8 * scale);
  // All external forces on the disc balance: plate + inferior + probe + nodal.
  EXPECT_LT((F_plate + F_inf + fp[0] - F_nodal).norm(), 1e-8 * scale);
}

TEST_F(SolverBox, TenPercentCompressionConverges) {
  const StaticResult r =
      solve_static(model_, fixtures::motion_boundary(mesh_, vec6(0, -0.8, 0, 0, 0, 0)));
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.reaction_wrench(1), 0.0);
  std::printf("box 10%% compression: %d Newton iterations, %.3f s, F_y = %.3f N, residual %.2e N\n",
              r.iterations, r.seconds, r.reaction_wrench(1), r.residual_n);
}

TEST_F(SolverBox, BadInputIsRefused) {
  Boundary bc = fixtures::motion_boundary(mesh_, Vector6d::Zero());
  bc.wrench(0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(solve_static(model_, bc), std::invalid_argument);
  bc = fixtures::motion_boundary(mesh_, Vector6d::Zero());
  EXPECT_THROW(solve_static(model_, bc, StaticOptions(), Eigen::VectorXd::Zero(5)),
               std::invalid_argument);
  StaticOptions bad;
  bad.max_iterations = 0;
  EXPECT_THROW(solve_static(model_, bc, bad), std::invalid_argument);
  bad = StaticOptions();
  bad.relative_tolerance = -1;
  EXPECT_THROW(solve_static(model_, bc, bad), std::invalid_argument);
  Eigen::VectorXd x = model_.rest_positions_mm();
  x(3) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(solve_static(model_, bc, StaticOptions(), x), std::invalid_argument);
  EXPECT_THROW(plate_reaction(model_, Eigen::VectorXd::Zero(2), c_), std::invalid_argument);
}

TEST_F(SolverBox, IterationLimitIsReportedNotHidden) {
  StaticOptions one;
  one.max_iterations = 1;
  const StaticResult r =
      solve_static(model_, fixtures::motion_boundary(mesh_, vec6(0, -0.8, 0, 0.02, 0, 0)), one);
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(r.iterations, 1);
  EXPECT_GT(r.residual_n, 0.0);
}

TEST_F(SolverBox, WholeDiscVolumeTermIsSolvedWithItsRankOneHessian) {
  // The whole-disc volume term couples every node: its Hessian's rank-one part is applied by
  // Sherman–Morrison. Without it Newton would still converge, but only linearly.
  MssOptions o;
  o.disc_volume_term = true;
  o.disc_volume_factor = 10.0;
  const MssModel model(mesh_, soft_and_softer(), o);
  const Boundary bc = fixtures::motion_boundary(mesh_, vec6(0.05, -0.8, 0.0, 0.02, 0.0, 0.0));
  const StaticResult r = solve_static(model, bc);
  ASSERT_TRUE(r.converged) << r.message;
  const StaticResult plain = solve_static(model_, bc);
  const double dv = model.volume_mm3(r.x_mm) / model.rest_volume_mm3() - 1.0;
  const double dv_plain = model_.volume_mm3(plain.x_mm) / model_.rest_volume_mm3() - 1.0;
  std::printf(
      "10%% compression with the whole-disc volume term: %d Newton iterations, volume change "
      "%.3f %% (without: %.3f %%)\n",
      r.iterations, 100 * dv, 100 * dv_plain);
  EXPECT_LE(r.iterations, plain.iterations + 2);
  EXPECT_LT(std::abs(dv), std::abs(dv_plain));
}

TEST(SolverDisc, L4L5TenPercentCompressionAndWrenchConverge) {
  const mesh::TetMesh& m = fixtures::l4_l5(3.5);
  const MssModel model(m, fixtures::real_disc());
  const StaticResult r =
      solve_static(model, fixtures::motion_boundary(m, vec6(0, -1.13, 0, 0, 0, 0)));
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.reaction_wrench(1), 0.0);
  std::printf(
      "L4-L5 (%ld tets, %ld nodes) 10%% compression: %d Newton iterations, %.3f s, F_y = %.1f N\n",
      long(m.num_tets()), long(m.num_vertices()), r.iterations, r.seconds, r.reaction_wrench(1));
  // The reaction of that compression, applied as a wrench, gives back about the same motion.
  const Vector6d w = -r.reaction_wrench;
  const StaticResult rw = solve_static(model, fixtures::wrench_boundary(m, w));
  EXPECT_TRUE(rw.converged) << rw.message;
  std::printf("  as a wrench: %d Newton iterations, %.3f s, plate motion %s\n", rw.iterations,
              rw.seconds,
              [&] {
                std::ostringstream o;
                o << rw.plate_motion.transpose();
                return o.str();
              }()
                  .c_str());
  // Pure translation: the plate map is exact, so the same equilibrium comes back (the moments
  // differ only through the moved centre, far below the axial term).
  EXPECT_NEAR(rw.plate_motion(1), -1.13, 1e-6);
  EXPECT_LT(rw.plate_motion.tail<3>().norm(), 1e-6);
}

}  // namespace
}  // namespace spinesim::mss
