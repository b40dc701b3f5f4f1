// Linear fibre families (fibres.hpp): the element term against the fibre energy and against an
// independent B^T D_f B quadrature; the patch test with fibres; the annulus fibre field.
#include "spinesim/common/constants.hpp"
#include "spinesim/fem/assembly.hpp"
#include "spinesim/fem/dirichlet.hpp"
#include "spinesim/fem/fibres.hpp"

#include "fibre_fixtures.hpp"
#include "spinesim/fem/mixed.hpp"
#include "spinesim/fem/quadrature.hpp"
#include "spinesim/mesh/annulus_frames.hpp"
#include "spinesim/mesh/box_mesh.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <functional>
#include <random>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

TetVertices sample_tet() {
  TetVertices X;
  X << 0.1, 0.0, 0.2,  //
      1.3, 0.2, 0.1,   //
      0.3, 1.1, -0.2,  //
      0.2, 0.4, 0.9;
  return X;
}

template <int NPE>
Eigen::Matrix<double, 3 * NPE, 1> nodal_values(
    const TetVertices& X, int order,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& u) {
  Eigen::Matrix<double, 3 * NPE, 1> ue;
  for (int a = 0; a < 4; ++a) ue.template segment<3>(3 * a) = u(X.row(a).transpose());
  if (order == 2)
    for (int e = 0; e < 6; ++e) {
      const Eigen::Vector3d mid =
          0.5 * (X.row(kP2LocalEdges[e][0]) + X.row(kP2LocalEdges[e][1])).transpose();
      ue.template segment<3>(3 * (4 + e)) = u(mid);
    }
  return ue;
}

TEST(FibreStiffness, UniformStretchAlongTheFibreStoresHalfKESquaredV) {
  const TetVertices X = sample_tet();
  double vol = 0;
  barycentric_gradients(X, vol);
  const Eigen::Vector3d a = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Vector3d b = a.unitOrthogonal();
  const double k = 42.0, e = 0.013;
  Eigen::Matrix<double, 30, 30> K = Eigen::Matrix<double, 30, 30>::Zero();
  add_fibre_stiffness(X, a, k, K);
  const auto along = nodal_values<10>(
      X, 2, [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return e * a.dot(x) * a; });
  EXPECT_NEAR(0.5 * along.dot(K * along), 0.5 * k * e * e * vol, 1e-13);
  // A stretch across the fibre, and a rigid rotation, store nothing.
  const auto across = nodal_values<10>(
      X, 2, [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return e * b.dot(x) * b; });
  const auto rotation = nodal_values<10>(X, 2, [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return Eigen::Vector3d(0.01, -0.02, 0.015).cross(x);
  });
  EXPECT_NEAR(across.dot(K * across), 0.0, 1e-15);
  EXPECT_NEAR(rotation.dot(K * rotation), 0.0, 1e-15);
  Eigen::Matrix<double, 12, 12> K1 = Eigen::Matrix<double, 12, 12>::Zero();
  add_fibre_stiffness(X, a, k, K1);
  const auto along1 = nodal_values<4>(
      X, 1, [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return e * a.dot(x) * a; });
  EXPECT_NEAR(0.5 * along1.dot(K1 * along1), 0.5 * k * e * e * vol, 1e-13);
}

TEST(FibreStiffness, EqualsBTransposeDfBByAnIndependentQuadrature) {
  // u^T K u = \int eps(u)^T D_f eps(u) dV, eps in Voigt form from the shape gradients, with the
  // 64-point collapsed rule and the Voigt matrix fibre_elasticity — a second route.
  const TetVertices X = sample_tet();
  const Eigen::Vector3d a = Eigen::Vector3d(-0.2, 0.9, 0.4).normalized();
  const double k = 17.0;
  Eigen::Matrix<double, 30, 30> K = Eigen::Matrix<double, 30, 30>::Zero();
  add_fibre_stiffness(X, a, k, K);
  const Matrix6d D = fibre_elasticity(a, k);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uni(-1, 1);
  const TetQuadrature q = tet_rule_collapsed(4);
  double vol = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, vol);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::Matrix<double, 30, 1> u;
    for (int i = 0; i < 30; ++i) u(i) = uni(rng);
    double energy = 0;
    for (Eigen::Index p = 0; p < q.weights.size(); ++p) {
      const Eigen::MatrixX3d G = shape_gradients(2, gL, q.barycentric.row(p).transpose());
      Eigen::Matrix3d grad = Eigen::Matrix3d::Zero();
      for (int n = 0; n < 10; ++n) grad += u.segment<3>(3 * n) * G.row(n);
      const Eigen::Matrix3d eps = 0.5 * (grad + grad.transpose());
      Vector6d v;
      v << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(1, 2), 2 * eps(0, 2), 2 * eps(0, 1);
      energy += q.weights(p) * vol * v.dot(D * v);
    }
    EXPECT_NEAR(u.dot(K * u), energy, 1e-11 * std::abs(energy));
  }
}

TEST(FibreStiffness, PatchTestWithUniformFibresDisplacementAndMixed) {
  mesh::TetMesh m = mesh::unit_cube_mesh(3);
  mesh::perturb_interior(m, 1.0 / 3, 0.15);
  mesh::RegionMaterials mat;
  mat.fallback = {2.0, 0.45, 1000.0};
  ElementFibres fib;
  const Eigen::Index nt = m.num_tets();
  const Eigen::RowVector3d a1 = Eigen::RowVector3d(0.8, 0.5, 0.3).normalized();
  const Eigen::RowVector3d a2 = Eigen::RowVector3d(0.8, -0.5, 0.3).normalized();
  fib.direction_1 = a1.replicate(nt, 1);
  fib.direction_2 = a2.replicate(nt, 1);
  fib.stiffness_mpa.setConstant(nt, 50.0);
  Eigen::Matrix3d G;
  G << 0.01, 0.02, -0.03, 0.005, -0.01, 0.015, 0.02, 0.01, 0.03;
  for (bool mixed : {false, true}) {
    const FeSpace space = make_fe_space(m, 2);
    const PressureSpace ps = make_pressure_space(m.T, m.region);
    const Eigen::SparseMatrix<double> K = mixed ? assemble_mixed(space, ps, m.region, mat, &fib)
                                                : assemble_stiffness(space, m.region, mat, &fib);
    std::vector<Eigen::Index> dofs;
    std::vector<double> values;
    for (Eigen::Index i = 0; i < space.num_nodes(); ++i) {
      const Eigen::Vector3d x = space.X.row(i).transpose();
      if ((x.array().abs() < 1e-12).any() || ((x.array() - 1).abs() < 1e-12).any())
        for (int d = 0; d < 3; ++d) dofs.push_back(3 * i + d), values.push_back((G * x)(d));
    }
    const Eigen::VectorXd u = solve_dirichlet(
        K, Eigen::VectorXd::Zero(K.rows()), dofs,
        Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size())),
        mixed ? Factorization::ldlt : Factorization::llt);
    double err = 0;
    for (Eigen::Index i = 0; i < space.num_nodes(); ++i)
      err = std::max(err, (u.segment<3>(3 * i) - G * space.X.row(i).transpose()).norm());
    EXPECT_LT(err, 1e-12) << (mixed ? "mixed" : "displacement");
  }
}

using test::fibre_annulus;

mesh::TetMesh sample_disc(const mesh::DiscFrame& placement = {}) {
  return test::structured_test_disc(24, 6, 3, placement);
}

TEST(FibreField, FollowsTheOutlineAtTheLamellaAngle) {
  const mesh::TetMesh m = sample_disc();
  const mesh::RegionMaterials mat = fibre_annulus();
  const ElementFibres f = fibre_field(m, mat);
  const Eigen::Vector3d axis = m.frame.axes.col(1);
  int annulus = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    if (m.region(t) != 1) {
      EXPECT_EQ(f.stiffness_mpa(t), 0.0);
      continue;
    }
    ++annulus;
    const double s = f.depth(t);
    ASSERT_TRUE(s >= 0 && s <= 1) << s;
    const double alpha = 45 + (28 - 45) * s;
    EXPECT_NEAR(f.angle_deg(t), alpha, 1e-12);
    EXPECT_NEAR(f.stiffness_mpa(t), 0.5 * (60 + 80 * s), 1e-12);
    for (const Eigen::Vector3d a : {Eigen::Vector3d(f.direction_1.row(t).transpose()),
                                    Eigen::Vector3d(f.direction_2.row(t).transpose())}) {
      EXPECT_NEAR(a.norm(), 1.0, 1e-12);
      EXPECT_NEAR(std::asin(std::abs(a.dot(axis))) * 180 / kPi, alpha, 1e-9);
    }
    // The two families mirror each other about the transverse plane.
    EXPECT_NEAR(f.direction_1.row(t).dot(axis), -f.direction_2.row(t).dot(axis), 1e-12);
  }
  EXPECT_GT(annulus, 100);
}

TEST(FibreField, CircumferentialIsTangentToTheOutlineAndDepthGrowsOutwards) {
  const mesh::TetMesh m = sample_disc();
  const mesh::AnnulusFrames fr = mesh::annulus_frames(m);
  const Eigen::Vector3d axis = m.frame.axes.col(1);
  double min_dot = 1, mean_dot = 0, inner_depth = 0, outer_depth = 0;
  int n = 0, n_inner = 0, n_outer = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) {
    if (m.region(t) != 1) continue;
    const Eigen::Vector3d c =
        (m.V.row(m.T(t, 0)) + m.V.row(m.T(t, 1)) + m.V.row(m.T(t, 2)) + m.V.row(m.T(t, 3)))
            .transpose() /
        4;
    Eigen::Vector3d out = c - m.frame.origin_mm;
    out -= out.dot(axis) * axis;
    const Eigen::Vector3d e_c = fr.circumferential.row(t).transpose();
    const Eigen::Vector3d e_r = fr.radial.row(t).transpose();
    EXPECT_NEAR(e_c.dot(axis), 0.0, 1e-12);
    EXPECT_NEAR(e_c.dot(e_r), 0.0, 1e-12);
    const double d = e_r.dot(out.normalized());
    min_dot = std::min(min_dot, d);
    mean_dot += d;
    ++n;
    // Radius of the centroid relative to the outline along its ray: a fraction.
    const double r = out.norm();
    if (r < 0.72 * 25) inner_depth += fr.depth(t), ++n_inner;  // near the nucleus (sqrt 0.4)
    if (r > 0.95 * 18) outer_depth += fr.depth(t), ++n_outer;
  }
  mean_dot /= n;
  EXPECT_GT(mean_dot, 0.95);
  EXPECT_GT(min_dot, 0.3);
  ASSERT_GT(n_inner, 0);
  ASSERT_GT(n_outer, 0);
  EXPECT_LT(inner_depth / n_inner, outer_depth / n_outer);
}

TEST(FibreField, TurnsWithTheDisc) {
  mesh::DiscFrame placed;
  placed.origin_mm = Eigen::Vector3d(3, -40, 7);
  placed.axes =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 0.2, -0.3).normalized()).toRotationMatrix();
  const mesh::TetMesh upright = sample_disc(), moved = sample_disc(placed);
  const ElementFibres a = fibre_field(upright, fibre_annulus());
  const ElementFibres b = fibre_field(moved, fibre_annulus());
  ASSERT_EQ(a.stiffness_mpa.size(), b.stiffness_mpa.size());
  const Eigen::MatrixX3d rotated = a.direction_1 * placed.axes.transpose();
  for (Eigen::Index t = 0; t < upright.num_tets(); ++t) {
    if (upright.region(t) != 1) continue;
    EXPECT_LT((rotated.row(t) - b.direction_1.row(t)).norm(), 1e-9) << t;
    EXPECT_NEAR(a.depth(t), b.depth(t), 1e-9) << t;
  }
}

// A mesh that brings fibre paths (a peer's fibres) sets the directions tet by tet: the field
// takes them normalised, reports their inclination in the lamella frame as alpha, keeps E_f by
// depth, and falls back to the lamella angle in tets whose paths are zero.
TEST(FibreField, FollowsTheMeshsFibrePathsAndKeepsTheStiffnessByDepth) {
  const mesh::TetMesh bare = sample_disc();
  const ElementFibres geometric = fibre_field(bare, fibre_annulus());
  const mesh::AnnulusFrames fr = mesh::annulus_frames(bare);
  mesh::TetMesh m = bare;
  const Eigen::Index nt = m.num_tets();
  m.fibre_paths.direction_1.setZero(nt, 3);
  m.fibre_paths.direction_2.setZero(nt, 3);
  const double beta = 20.0 * kRadPerDeg;  // the peer's angle, not the material's
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (m.region(t) != 1 || t % 7 == 0) continue;  // every 7th annulus tet: no path
    const Eigen::RowVector3d c = std::cos(beta) * fr.circumferential.row(t);
    const Eigen::RowVector3d z = std::sin(beta) * fr.axial.row(t);
    // Both families given a little long (as a Float32 copy might be): they are normalised.
    m.fibre_paths.direction_1.row(t) = (1 + 5e-5) * (c + z);
    m.fibre_paths.direction_2.row(t) = (1 - 5e-5) * (c - z);
  }
  mesh::validate(m);
  const ElementFibres f = fibre_field(m, fibre_annulus());
  int followed = 0, fell_back = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    EXPECT_EQ(f.stiffness_mpa(t), geometric.stiffness_mpa(t)) << t;
    if (!(geometric.stiffness_mpa(t) > 0)) {
      EXPECT_EQ(f.direction_1.row(t).norm(), 0.0);
      continue;
    }
    EXPECT_EQ(f.toe_k2(t), geometric.toe_k2(t));
    if (t % 7 == 0) {
      ++fell_back;
      EXPECT_EQ((f.direction_1.row(t) - geometric.direction_1.row(t)).norm(), 0.0) << t;
      EXPECT_EQ(f.angle_deg(t), geometric.angle_deg(t));
      continue;
    }
    ++followed;
    EXPECT_LT((f.direction_1.row(t) - m.fibre_paths.direction_1.row(t).normalized()).norm(), 1e-15);
    EXPECT_LT((f.direction_2.row(t) - m.fibre_paths.direction_2.row(t).normalized()).norm(), 1e-15);
    EXPECT_NEAR(f.direction_1.row(t).norm(), 1.0, 1e-15);
    EXPECT_NEAR(f.angle_deg(t), 20.0, 1e-9);
  }
  EXPECT_GT(followed, 100);
  EXPECT_GT(fell_back, 10);
}

}  // namespace
