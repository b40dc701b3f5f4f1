// ContactDisc: the condensed contact solve against a brute-force Newton solve of the whole
// system (the penalty Hessian added to the full stiffness, no condensation, no cached columns),
// its sphere stiffness against finite differences of the force, and its bookkeeping.
#include "../haptics/disc_fixture.hpp"
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/contact_disc.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <cmath>

using namespace spinesim;
using Eigen::Vector3d;

namespace {

const mesh::TetMesh& disc_mesh() { return spinesim::test::structured_l4l5_disc(); }

const mesh::RegionMaterials& material() {
  static const mesh::RegionMaterials m = mesh::load_material("fibre-reinforced", SPINESIM_DATA_DIR);
  return m;
}

Vector3d anterior_wall() { return spinesim::test::anterior_wall(disc_mesh()).first; }

/// Brute force: Newton on the whole free system K u - f(u) = 0 with the exact penalty Hessian,
/// every wall node a candidate, Eigen's own sparse Cholesky. Returns the positions (3 #V).
Eigen::VectorXd brute_force(const Vector3d& c, double r, double k_p) {
  const mesh::TetMesh& m = disc_mesh();
  const fem::FeSpace space = fem::make_fe_space(m, 1);
  std::vector<fem::NodeRole> roles(std::size_t(m.num_vertices()), fem::NodeRole::free);
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i)
    if (m.surface(i) == 1 || m.surface(i) == 2) roles[std::size_t(i)] = fem::NodeRole::fixed;
  fem::FreeBlockPattern p = fem::build_free_block_pattern(space, roles, fem::FreeNodeOrder::node);
  const auto fibres = fem::fibre_field(m, material());
  fem::assemble_constrained(space, m.region, material(), roles, Vector3d::Zero(), p, &fibres);
  const Eigen::SparseMatrix<double> K = p.lower.selfadjointView<Eigen::Lower>();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(K.rows());
  auto X = [&](Eigen::Index i) { return Vector3d(m.V.row(i).transpose()); };
  // The total energy u.K u/2 + sum k_p/2 pen^2, its gradient and Gauss-Newton Hessian blocks.
  auto energy = [&](const Eigen::VectorXd& v, Eigen::VectorXd* g,
                    std::vector<Eigen::Triplet<double>>* h) {
    const Eigen::VectorXd Kv = K * v;
    double e = 0.5 * v.dot(Kv);
    if (g) *g = Kv;
    for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
      if (m.surface(i) != 3) continue;
      const Eigen::Index a = 3 * p.free_index[std::size_t(i)];
      const Vector3d d = c - (X(i) + v.segment<3>(a));
      const double dist = d.norm(), pen = r - dist;
      if (!(pen > 0)) continue;
      e += 0.5 * k_p * pen * pen;
      const Vector3d n = d / dist;
      if (g) g->segment<3>(a) += k_p * pen * n;  // -f_i
      if (h) {
        const Eigen::Matrix3d D = k_p * n * n.transpose();
        for (int x = 0; x < 3; ++x)
          for (int y = 0; y < 3; ++y) h->emplace_back(a + x, a + y, D(x, y));
      }
    }
    return e;
  };
  for (int it = 0; it < 200; ++it) {
    Eigen::VectorXd g;
    std::vector<Eigen::Triplet<double>> h;
    const double e = energy(u, &g, &h);
    if (g.norm() < 1e-12 * (K * u).norm() + 1e-14) break;
    Eigen::SparseMatrix<double> Dm(K.rows(), K.cols());
    Dm.setFromTriplets(h.begin(), h.end());
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(K + Dm);
    const Eigen::VectorXd step = -ldlt.solve(g);
    double alpha = 1;
    while (energy(u + alpha * step, nullptr, nullptr) > e + 1e-4 * alpha * g.dot(step) &&
           alpha > 1e-10)
      alpha *= 0.5;
    u += alpha * step;
    if (alpha * step.norm() < 1e-15 * (1 + u.norm())) break;
  }
  Eigen::VectorXd x(3 * m.num_vertices());
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    x.segment<3>(3 * i) = X(i);
    if (p.free_index[std::size_t(i)] >= 0)
      x.segment<3>(3 * i) += u.segment<3>(3 * p.free_index[std::size_t(i)]);
  }
  return x;
}

}  // namespace

TEST(ContactDisc, PressedEquilibriumMatchesABruteForceSolveOfTheWholeSystem) {
  fem::ContactDisc disc(disc_mesh(), material());
  const double r = 4;
  // The sphere's centre 1.5 mm inside the anterior wall's surface, a little off the node.
  const Vector3d c = anterior_wall() + Vector3d(0.7, 0.4, r - 1.5);
  const fem::ContactSolveReport rep = disc.solve(c);
  ASSERT_TRUE(rep.ok);
  EXPECT_GT(rep.in_contact, 0);
  const Eigen::VectorXd oracle = brute_force(c, r, disc.penalty_n_per_mm());
  const Eigen::VectorXd u = disc.positions_mm() - disc.rest_positions_mm();
  const Eigen::VectorXd u_ref = oracle - disc.rest_positions_mm();
  ASSERT_GT(u_ref.lpNorm<Eigen::Infinity>(), 0.05);  // the disc is really pressed
  EXPECT_LT((u - u_ref).lpNorm<Eigen::Infinity>(), 1e-8 * u_ref.lpNorm<Eigen::Infinity>());
  // The force on the sphere points out of the disc (+z) and equals the nodes' reactions.
  EXPECT_GT(disc.probe_force_n().z(), 0);
  // Pressing in compresses the disc's volume a little; never expands it by much.
  EXPECT_LT(std::abs(disc.volume_change()), 1e-2);
}

TEST(ContactDisc, SphereStiffnessIsTheDerivativeOfTheForce) {
  fem::ContactDisc disc(disc_mesh(), material());
  const Vector3d c = anterior_wall() + Vector3d(0.3, -0.2, 4 - 1.0);
  ASSERT_TRUE(disc.solve(c).ok);
  const Eigen::Matrix3d K = disc.probe_stiffness();
  EXPECT_LT((K - K.transpose()).norm(), 1e-9 * K.norm());
  const double h = 1e-4;
  Eigen::Matrix3d fd;
  for (int k = 0; k < 3; ++k) {
    const Vector3d e = h * Vector3d::Unit(k);
    ASSERT_TRUE(disc.solve(c + e).ok);
    const Vector3d fp = disc.probe_force_n();
    ASSERT_TRUE(disc.solve(c - e).ok);
    const Vector3d fm = disc.probe_force_n();
    fd.col(k) = -(fp - fm) / (2 * h);
  }
  EXPECT_LT((fd - K).norm(), 1e-4 * K.norm()) << "K\n" << K << "\nfd\n" << fd;
  // Stiffer across the wall than along it: the normal direction carries the contact.
  EXPECT_GT(K(2, 2), K(0, 0));
  // The normal springs' part: symmetric positive semi-definite, and the curvature term it leaves
  // out only softens the directions along the wall (the normal entries agree to a few per cent).
  const Eigen::Matrix3d Kgn = disc.probe_stiffness_gauss_newton();
  EXPECT_LT((Kgn - Kgn.transpose()).norm(), 1e-9 * Kgn.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Kgn).eigenvalues().minCoeff(),
            -1e-9 * Kgn.norm());
  EXPECT_GE(Kgn(0, 0), K(0, 0));
  EXPECT_GE(Kgn(1, 1), K(1, 1));
  EXPECT_NEAR(Kgn(2, 2), K(2, 2), 0.05 * K(2, 2));
}

TEST(ContactDisc, FreeOfTheDiscNothingMovesAndColumnsAreCachedAndBounded) {
  fem::ContactDiscOptions o;
  o.max_cache_mb = 1e-6;  // the 16 nodes kept whatever the budget
  fem::ContactDisc disc(disc_mesh(), material(), o);
  const Vector3d wall = anterior_wall();
  ASSERT_TRUE(disc.solve(wall + Vector3d(0, 0, 20)).ok);
  EXPECT_EQ(disc.probe_force_n(), Vector3d::Zero());
  EXPECT_EQ(disc.positions_mm(), disc.rest_positions_mm());
  EXPECT_EQ(disc.column_solves(), 0);
  const Vector3d c = wall + Vector3d(0, 0, 4 - 1.0);
  ASSERT_TRUE(disc.solve(c).ok);
  const auto solved = disc.column_solves();
  EXPECT_GT(solved, 0);
  const Vector3d f = disc.probe_force_n();
  ASSERT_TRUE(disc.solve(c).ok);  // the same press: no new columns, the same answer
  EXPECT_EQ(disc.column_solves(), solved);
  EXPECT_LT((disc.probe_force_n() - f).norm(), 1e-9 * f.norm());
  // Sliding along the wall meets new nodes; the cache stays within its bound and the answer
  // back at the start is the same.
  for (int k = 1; k <= 20; ++k) ASSERT_TRUE(disc.solve(c + Vector3d(0.5 * k, 0, 0)).ok);
  EXPECT_GT(disc.column_solves(), solved);
  EXPECT_LE(disc.cached_nodes(), 16u);
  ASSERT_TRUE(disc.solve(c).ok);
  EXPECT_LT((disc.probe_force_n() - f).norm(), 1e-8 * f.norm());
}

TEST(ContactDisc, RefusesBadInput) {
  fem::ContactDiscOptions o;
  o.probe_radius_mm = -1;
  EXPECT_THROW(fem::ContactDisc(disc_mesh(), material(), o), std::invalid_argument);
  mesh::TetMesh unlabelled = disc_mesh();
  unlabelled.surface.setZero();
  EXPECT_THROW(fem::ContactDisc(unlabelled, material()), std::invalid_argument);
}
