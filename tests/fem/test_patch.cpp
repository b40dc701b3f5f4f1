// Patch test: a linear displacement field imposed on every boundary node of a distorted
// unit-cube mesh is reproduced at the interior nodes to round-off, with constant stress
// sigma = D eps(A), by P1 and P2 (Zienkiewicz & Taylor vol. 1, ch. 10).
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/dirichlet.hpp"
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <set>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

struct LinearField {
  Eigen::Matrix3d A;
  Eigen::Vector3d b;
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return A * x + b; }
};

void run_patch_test(int order) {
  mesh::TetMesh m = spinesim::mesh::unit_cube_mesh(4);
  spinesim::mesh::perturb_interior(m, 0.25, 0.15);
  mesh::validate(m);
  mesh::RegionMaterials mat;
  mat.fallback = {7.0, 0.35, 1000.0};

  const FeSpace space = make_fe_space(m, order);
  const Eigen::SparseMatrix<double> K = assemble_stiffness(space, m.region, mat);
  LinearField field;
  field.A << 0.01, 0.02, -0.03, 0.005, -0.01, 0.015, 0.02, 0.01, 0.03;
  field.b << 0.1, -0.2, 0.05;

  // Boundary nodes: P1 vertices on the boundary; P2 also edge nodes with both ends there
  // (an edge between two boundary vertices through the interior does not occur on this grid's
  // faces-only boundary, and if it did, prescribing the exact linear value would still be right).
  std::set<int> bverts;
  for (int v : spinesim::mesh::boundary_vertices(m)) bverts.insert(v);
  std::vector<Eigen::Index> fixed;
  std::vector<double> values;
  std::vector<char> is_fixed(std::size_t(space.num_nodes()), 0);
  const auto add = [&](Eigen::Index node) {
    is_fixed[std::size_t(node)] = 1;
    const Eigen::Vector3d u = field(space.X.row(node).transpose());
    for (int d = 0; d < 3; ++d) fixed.push_back(3 * node + d), values.push_back(u(d));
  };
  for (int v : bverts) add(v);
  for (Eigen::Index e = 0; e < space.edge_vertices.rows(); ++e) {
    const Eigen::Vector3d mid = space.X.row(space.num_vertices + e).transpose();
    const bool on_face =
        (mid.array().abs() < 1e-12).any() || ((mid.array() - 1).abs() < 1e-12).any();
    if (on_face) add(space.num_vertices + e);
  }
  const Eigen::VectorXd u = solve_dirichlet(
      K, Eigen::VectorXd::Zero(K.rows()), fixed,
      Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())));
  double max_err = 0, max_u = 0;
  Eigen::Index interior = 0;
  for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
    if (is_fixed[std::size_t(i)]) continue;
    ++interior;
    const Eigen::Vector3d exact = field(space.X.row(i).transpose());
    max_err = std::max(max_err, (u.segment<3>(3 * i) - exact).norm());
    max_u = std::max(max_u, exact.norm());
  }
  EXPECT_GT(interior, 0);
  EXPECT_LT(max_err, 1e-12 * max_u) << "P" << order << " patch test, max nodal error " << max_err;

  // Constant stress D eps(A) at several points of every element.
  const Eigen::Matrix3d eps = 0.5 * (field.A + field.A.transpose());
  Vector6d e;
  e << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(1, 2), 2 * eps(0, 2), 2 * eps(0, 1);
  const Vector6d sigma = isotropic_elasticity(mat.fallback) * e;
  double max_stress_err = 0;
  const int npe = space.nodes_per_element();
  for (Eigen::Index t = 0; t < space.elements.rows(); ++t) {
    TetVertices X;
    for (int a = 0; a < 4; ++a) X.row(a) = space.X.row(space.elements(t, a));
    Eigen::VectorXd ue(3 * npe);
    for (int a = 0; a < npe; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * space.elements(t, a));
    for (const Eigen::Vector4d& L :
         {Eigen::Vector4d(0.25, 0.25, 0.25, 0.25), Eigen::Vector4d(1, 0, 0, 0),
          Eigen::Vector4d(0.1, 0.2, 0.3, 0.4)})
      max_stress_err =
          std::max(max_stress_err, (element_stress(order, X, mat.fallback, ue, L) - sigma).norm());
  }
  EXPECT_LT(max_stress_err, 1e-10 * sigma.norm()) << "P" << order << " stress not constant";
}

}  // namespace

TEST(PatchTest, P1ReproducesLinearFieldAndConstantStress) { run_patch_test(1); }
TEST(PatchTest, P2ReproducesLinearFieldAndConstantStress) { run_patch_test(2); }

TEST(Dirichlet, RejectsBadInput) {
  Eigen::SparseMatrix<double> K(3, 3);
  K.setIdentity();
  EXPECT_THROW(solve_dirichlet(K, Eigen::VectorXd::Zero(2), {}, Eigen::VectorXd()),
               std::invalid_argument);
  EXPECT_THROW(solve_dirichlet(K, Eigen::VectorXd::Zero(3), {5}, Eigen::VectorXd::Zero(1)),
               std::invalid_argument);
}
