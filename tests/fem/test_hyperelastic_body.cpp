// The nonlinear body solver on its own: at small loads it is the linear FEM (the same problem
// solved with the linear element stiffness), its reactions balance, a load it cannot carry ends
// in a failure that says so (never "converged"), and bad input is refused.
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/hyperelastic_body.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace spinesim::fem {
namespace {

struct Block {
  mesh::TetMesh mesh = mesh::box_mesh(2, 2, 2, 4.0, 4.0, 4.0);
  FeSpace space;
  Eigen::VectorXi labels;
  explicit Block(int order) : space(make_fe_space(mesh, order)) {
    labels = node_surface_labels(space, mesh);
  }
  std::vector<PrescribedDisplacement> moved(const Eigen::Vector3d& top) const {
    std::vector<PrescribedDisplacement> bc;
    for (Eigen::Index i = 0; i < space.num_nodes(); ++i)
      for (int d = 0; d < 3; ++d) {
        if (labels(i) == 1) bc.push_back({i, d, 0.0});
        if (labels(i) == 2) bc.push_back({i, d, top(d)});
      }
    return bc;
  }
};

/// The linear FEM of the same Dirichlet problem: K u = 0 on the free DOF, u prescribed.
Eigen::VectorXd linear_solution(const Block& b, const mesh::IsotropicMaterial& lin,
                                const std::vector<PrescribedDisplacement>& bc) {
  const Eigen::Index n = 3 * b.space.num_nodes();
  std::vector<Eigen::Triplet<double>> t;
  const int npe = b.space.nodes_per_element();
  for (Eigen::Index e = 0; e < b.space.elements.rows(); ++e) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = b.space.X.row(b.space.elements(e, a));
    const Eigen::MatrixXd K = element_stiffness(b.space.order, X, lin);
    for (int a = 0; a < 3 * npe; ++a)
      for (int c = 0; c < 3 * npe; ++c)
        t.emplace_back(3 * b.space.elements(e, a / 3) + a % 3,
                       3 * b.space.elements(e, c / 3) + c % 3, K(a, c));
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), rhs = Eigen::VectorXd::Zero(n);
  std::vector<bool> fixed(std::size_t(n), false);
  for (const auto& p : bc)
    u(3 * p.node + p.dof) = p.value_mm, fixed[std::size_t(3 * p.node + p.dof)] = true;
  // K_ff u_f = −K_fp u_p, the free DOF picked out by an index map.
  std::vector<Eigen::Index> free;
  for (Eigen::Index d = 0; d < n; ++d)
    if (!fixed[std::size_t(d)]) free.push_back(d);
  const Eigen::VectorXd Ku = K * u;
  Eigen::SparseMatrix<double> Kff(Eigen::Index(free.size()), Eigen::Index(free.size()));
  std::vector<Eigen::Index> index(std::size_t(n), -1);
  for (std::size_t k = 0; k < free.size(); ++k) index[std::size_t(free[k])] = Eigen::Index(k);
  std::vector<Eigen::Triplet<double>> tf;
  for (Eigen::Index c = 0; c < K.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, c); it; ++it)
      if (index[std::size_t(it.row())] >= 0 && index[std::size_t(it.col())] >= 0)
        tf.emplace_back(index[std::size_t(it.row())], index[std::size_t(it.col())], it.value());
  Kff.setFromTriplets(tf.begin(), tf.end());
  Eigen::VectorXd bf(Eigen::Index(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k) bf(Eigen::Index(k)) = -Ku(free[k]);
  const Eigen::VectorXd uf = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(Kff).solve(bf);
  for (std::size_t k = 0; k < free.size(); ++k) u(free[k]) = uf(Eigen::Index(k));
  return u;
}

class SmallLoads : public ::testing::TestWithParam<int> {};

TEST_P(SmallLoads, TheNonlinearBodyIsTheLinearFemAtSmallLoads) {
  const Block b(GetParam());
  const mesh::IsotropicMaterial lin{4.2, 0.45, 1000.0};
  const FibreHyperelastic m = neo_hookean_from_linear(lin.youngs_modulus_mpa, lin.poisson_ratio);
  const HyperelasticBody body(b.space,
                              std::vector<FibreHyperelastic>(std::size_t(b.mesh.num_tets()), m));
  // The difference is second order in the load, so relative to the solution it is first order:
  // it falls 10x when the load falls 10x.
  std::vector<double> gaps;
  for (const double scale : {1e-2, 1e-3}) {
    const auto bc = b.moved(scale * Eigen::Vector3d(0.3, -0.4, 0.1));
    const HyperelasticSolution s = body.solve(bc);
    ASSERT_TRUE(s.converged) << s.failure;
    const Eigen::VectorXd unl = linear_solution(b, lin, bc);  // node-major, as ours
    Eigen::VectorXd ours(unl.size());
    for (Eigen::Index i = 0; i < b.space.num_nodes(); ++i)
      ours.segment<3>(3 * i) = s.displacement_mm.row(i).transpose();
    gaps.push_back((ours - unl).norm() / unl.norm());
  }
  EXPECT_LT(gaps[0], 1e-2);
  EXPECT_NEAR(gaps[1] / gaps[0], 0.1, 0.02) << gaps[0] << " then " << gaps[1];
}

INSTANTIATE_TEST_SUITE_P(P1AndP2, SmallLoads, ::testing::Values(1, 2));

TEST(HyperelasticBodySolve, ReactionsBalanceAndFreeNodesAreInEquilibrium) {
  const Block b(1);
  FibreHyperelastic m = neo_hookean_from_linear(4.2, 0.45);
  m.fibres.push_back({Eigen::Vector3d(1, 1, 0).normalized(), 2.0, 20.0});
  const HyperelasticBody body(b.space,
                              std::vector<FibreHyperelastic>(std::size_t(b.mesh.num_tets()), m));
  const HyperelasticSolution s = body.solve(b.moved(Eigen::Vector3d(0.4, -0.3, 0.2)));
  ASSERT_TRUE(s.converged) << s.failure;
  EXPECT_GE(s.increments, 4);
  // No external load: the reactions of base and top sum to zero.
  EXPECT_LE(s.reaction_n.colwise().sum().norm(), 1e-8 * s.reaction_n.norm());
  // Internal forces at the free nodes vanish.
  Eigen::VectorXd u(3 * b.space.num_nodes());
  for (Eigen::Index i = 0; i < b.space.num_nodes(); ++i)
    u.segment<3>(3 * i) = s.displacement_mm.row(i).transpose();
  const auto ev = body.evaluate(u, false);
  double worst = 0;
  for (Eigen::Index i = 0; i < b.space.num_nodes(); ++i)
    if (b.labels(i) != 1 && b.labels(i) != 2)
      worst = std::max(worst, ev.force.segment<3>(3 * i).norm());
  EXPECT_LE(worst, 1e-8 * s.reaction_n.norm());
}

TEST(HyperelasticBodySolve, ALoadItCannotCarryFailsAndSaysSo) {
  const Block b(1);
  const FibreHyperelastic m = neo_hookean_from_linear(4.2, 0.45);
  const HyperelasticBody body(b.space,
                              std::vector<FibreHyperelastic>(std::size_t(b.mesh.num_tets()), m));
  NewtonOptions o;
  o.max_cutbacks = 3;
  // The top pushed 6 mm down through a 4 mm block: no state without inverted elements.
  const HyperelasticSolution s = body.solve(b.moved(Eigen::Vector3d(0, -6.0, 0)), o);
  EXPECT_FALSE(s.converged);
  EXPECT_NE(s.failure.find("did not converge"), std::string::npos) << s.failure;
  EXPECT_GE(s.cutbacks, 3);
  // What is kept is the last converged state, short of the load.
  EXPECT_GT(s.displacement_mm.col(1).minCoeff(), -6.0);
}

TEST(HyperelasticBodySolve, BadInputIsRefused) {
  const Block b(1);
  const FibreHyperelastic m = neo_hookean_from_linear(4.2, 0.45);
  EXPECT_THROW(HyperelasticBody(b.space, {m}), std::invalid_argument);
  FibreHyperelastic bad = m;
  bad.c10_mpa = -1;
  EXPECT_THROW(HyperelasticBody(
                   b.space, std::vector<FibreHyperelastic>(std::size_t(b.mesh.num_tets()), bad)),
               std::invalid_argument);
  const HyperelasticBody body(b.space,
                              std::vector<FibreHyperelastic>(std::size_t(b.mesh.num_tets()), m));
  EXPECT_THROW(body.solve({{0, 0, 0.1}, {0, 0, 0.2}}), std::invalid_argument);  // twice
  EXPECT_THROW(body.solve({{b.space.num_nodes(), 0, 0.1}}), std::invalid_argument);
  EXPECT_THROW(body.solve({{0, 3, 0.1}}), std::invalid_argument);
  EXPECT_THROW(body.solve({{0, 1, NAN}}), std::invalid_argument);
  NewtonOptions o;
  o.load_increments = 0;
  EXPECT_THROW(body.solve({{0, 1, 0.1}}, o), std::invalid_argument);
}

}  // namespace
}  // namespace spinesim::fem
