// The per-tet output of a mass-spring state (quantities.hpp): the Green–Lagrange strain is
// exact under any affine motion and zero under a rigid one; the edge-spring forces carry the
// calibrated stiffness — with random region scales and per-spring multipliers, the energy
// sum_e f_e^2 / (2 k_e) over the unique edges equals the model's main-spring energy.
#include "spinesim/mss/quantities.hpp"

#include "solver_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <map>
#include <random>
#include <utility>

namespace spinesim::mss {
namespace {

/// The shared box with its x > 0 half nucleus, and the real disc with a softer nucleus: edges on
/// the interface carry both regions' parts.
mesh::TetMesh two_region_box() {
  mesh::TetMesh m = fixtures::small_box();
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    if (m.V(m.T(t, 0), 0) + m.V(m.T(t, 3), 0) > 0.0) m.region(t) = 2;
  return m;
}

mesh::RegionMaterials materials() {
  mesh::RegionMaterials m = fixtures::real_disc();
  m.by_region[2] = {1.0, 0.49, 1000.0};
  return m;
}

/// Positions x = A X + b of every node.
Eigen::VectorXd affine(const MssModel& model, const Eigen::Matrix3d& A, const Eigen::Vector3d& b) {
  Eigen::VectorXd x = model.rest_positions_mm();
  for (Eigen::Index i = 0; i < model.num_nodes(); ++i) x.segment<3>(3 * i) = A * x.segment<3>(3 * i) + b;
  return x;
}

}  // namespace

TEST(MssStateFields, GreenLagrangeStrainIsExactForAffineMotionAndZeroForRigid) {
  const MssModel model(two_region_box(), materials());
  Eigen::Matrix3d A;
  A << 1.05, 0.02, -0.01, 0.03, 0.9, 0.04, 0.0, -0.02, 1.1;
  const Eigen::Matrix3d E = 0.5 * (A.transpose() * A - Eigen::Matrix3d::Identity());
  const Eigen::MatrixXd got = tet_green_lagrange_strain(model, affine(model, A, {1, 2, 3}));
  for (Eigen::Index t = 0; t < got.rows(); ++t) {
    Eigen::Matrix<double, 1, 6> want;
    want << E(0, 0), E(1, 1), E(2, 2), E(0, 1), E(1, 2), E(0, 2);
    EXPECT_LT((got.row(t) - want).norm(), 1e-13) << t;
  }
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::VectorXd rigid = affine(model, R, {5, -1, 2});
  EXPECT_LT(tet_green_lagrange_strain(model, rigid).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT(tet_edge_spring_forces(model, rigid).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(MssStateFields, EdgeSpringForcesCarryTheCalibratedStiffness) {
  const mesh::TetMesh mesh = two_region_box();
  MssOptions o;
  o.scales[int(Term::main)].by_region = {1.7, 0.6};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> mu(0.2, 5.0), jiggle(-0.3, 0.3);
  const Eigen::Index edges = MssModel(mesh, materials()).num_edge_springs();
  for (Eigen::Index e = 0; e < edges; ++e) o.edge_multipliers.push_back(mu(rng));
  const MssModel model(mesh, materials(), o);
  Eigen::VectorXd x = model.rest_positions_mm();
  for (Eigen::Index k = 0; k < x.size(); ++k) x(k) += jiggle(rng);
  const Eigen::MatrixXd f = tet_edge_spring_forces(model, x);
  // One force per unique edge, the same in every tet that shares it.
  std::map<std::pair<int, int>, double> force;
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (Eigen::Index t = 0; t < mesh.num_tets(); ++t)
    for (int k = 0; k < 6; ++k) {
      const int a = mesh.T(t, kEdges[k][0]), b = mesh.T(t, kEdges[k][1]);
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      if (force.count(key)) EXPECT_EQ(force[key], f(t, k));
      force[key] = f(t, k);
    }
  ASSERT_EQ(Eigen::Index(force.size()), edges);
  double energy = 0;
  for (const EdgeSpringInfo& e : model.edge_springs())
    energy += force[{e.i, e.j}] * force[{e.i, e.j}] / (2 * e.multiplier * e.k_region);
  const double main = 1.7 * model.term_energy(x, Term::main, 0) + 0.6 * model.term_energy(x, Term::main, 1);
  EXPECT_NEAR(energy, main, 1e-10 * main);
  EXPECT_GT(main, 0.0);
}

}  // namespace spinesim::mss
