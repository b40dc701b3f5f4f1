// Element kernels: quadrature exactness, stiffness symmetry and rigid-body null space, and the
// P2 stiffness against an independent energy integral (stress × strain with a high-order rule).
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/quadrature.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

TetVertices skewed_tet() {
  TetVertices X;
  X << 0.1, -0.2, 0.3,  //
      2.0, 0.1, -0.1,   //
      0.4, 1.7, 0.2,    //
      0.3, 0.5, 1.9;
  return X;
}

mesh::IsotropicMaterial rubbery() { return {3.0, 0.45, 1000.0}; }

// 6 rigid-body modes at points X (rows), node-major DOFs.
Eigen::MatrixXd rigid_modes(const Eigen::MatrixX3d& X) {
  Eigen::MatrixXd M(3 * X.rows(), 6);
  for (Eigen::Index a = 0; a < X.rows(); ++a) {
    const Eigen::Vector3d x = X.row(a).transpose();
    M.block<3, 3>(3 * a, 0).setIdentity();
    M.block<3, 3>(3 * a, 3) << 0, x.z(), -x.y(), -x.z(), 0, x.x(), x.y(), -x.x(), 0;
  }
  return M;
}

Eigen::MatrixX3d element_nodes(int order, const TetVertices& X) {
  if (order == 1) return X;
  Eigen::MatrixX3d N(10, 3);
  N.topRows<4>() = X;
  const int e[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (int k = 0; k < 6; ++k) N.row(4 + k) = 0.5 * (X.row(e[k][0]) + X.row(e[k][1]));
  return N;
}

}  // namespace

TEST(Quadrature, CollapsedRuleIsExactForMonomials) {
  // \int_T x^a y^b z^c = a! b! c! / (a+b+c+3)! on the unit tet.
  for (int n : {2, 3, 5}) {
    const TetQuadrature q = tet_rule_collapsed(n);
    EXPECT_NEAR(q.weights.sum(), 1.0, 1e-14);
    for (int a = 0; a <= 4; ++a)
      for (int b = 0; b <= 4 - a; ++b)
        for (int c = 0; c <= 4 - a - b; ++c) {
          if (a + b + c > 2 * n - 3) continue;
          double s = 0;
          for (Eigen::Index k = 0; k < q.weights.size(); ++k)
            s += q.weights(k) / 6.0 * std::pow(q.barycentric(k, 1), a) *
                 std::pow(q.barycentric(k, 2), b) * std::pow(q.barycentric(k, 3), c);
          const double exact =
              factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
          EXPECT_NEAR(s, exact, 1e-14) << "n=" << n << " a,b,c=" << a << b << c;
        }
  }
}

TEST(Quadrature, Degree2RuleIsExactForQuadratics) {
  const TetQuadrature q = tet_rule_degree2();
  const auto integrate = [&](int i, int j) {
    double s = 0;
    for (int k = 0; k < 4; ++k) s += q.weights(k) * q.barycentric(k, i) * q.barycentric(k, j);
    return s;
  };
  // mean of L_i L_j over a tet: 1/10 (i = j), 1/20 (i != j)
  EXPECT_NEAR(integrate(0, 0), 0.1, 1e-14);
  EXPECT_NEAR(integrate(1, 2), 0.05, 1e-14);
}

TEST(ElementStiffness, SymmetricWithSixRigidModesInNullSpace) {
  for (int order : {1, 2}) {
    const Eigen::MatrixXd K = element_stiffness(order, skewed_tet(), rubbery());
    EXPECT_LT((K - K.transpose()).norm(), 1e-13 * K.norm()) << "order " << order;
    const Eigen::MatrixXd R = rigid_modes(element_nodes(order, skewed_tet()));
    EXPECT_LT((K * R).norm(), 1e-12 * K.norm()) << "order " << order;
    // Exactly 6 zero eigenvalues, the rest positive.
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K);
    const Eigen::VectorXd ev = eig.eigenvalues();
    for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(ev(i)), 1e-10 * ev.maxCoeff());
    EXPECT_GT(ev(6), 1e-6 * ev.maxCoeff()) << "order " << order;
  }
}

TEST(ElementStiffness, EnergyMatchesHighOrderIntegralOfStressTimesStrain) {
  // For a field the element represents exactly, u^T K u = \int sigma : eps dV.
  const TetVertices X = skewed_tet();
  double vol = 0;
  barycentric_gradients(X, vol);
  const TetQuadrature q = tet_rule_collapsed(4);
  const mesh::IsotropicMaterial m = rubbery();
  for (int order : {1, 2}) {
    const Eigen::MatrixX3d N = element_nodes(order, X);
    Eigen::VectorXd ue(3 * N.rows());
    for (Eigen::Index a = 0; a < N.rows(); ++a) {  // linear (P1) or quadratic (P2) field
      const Eigen::Vector3d x = N.row(a).transpose();
      ue.segment<3>(3 * a) << 0.1 * x.y() + 0.02 * x.z(), -0.05 * x.x() + 0.03 * x.y(),
          0.04 * x.z();
      if (order == 2)
        ue.segment<3>(3 * a) +=
            Eigen::Vector3d(0.07 * x.x() * x.y(), -0.02 * x.z() * x.z(), 0.05 * x.x() * x.x());
    }
    double energy = 0;
    const Matrix6d D = isotropic_elasticity(m);
    for (Eigen::Index k = 0; k < q.weights.size(); ++k) {
      const Vector6d s = element_stress(order, X, m, ue, q.barycentric.row(k).transpose());
      const Vector6d e = D.ldlt().solve(s);
      energy += q.weights(k) * vol * s.dot(e);
    }
    const Eigen::MatrixXd K = element_stiffness(order, X, m);
    EXPECT_NEAR(ue.dot(K * ue), energy, 1e-12 * energy) << "order " << order;
  }
}

TEST(Elasticity, DMatrixMatchesLameConstants) {
  const mesh::IsotropicMaterial m{10.0, 0.3, 1000.0};
  const Matrix6d D = isotropic_elasticity(m);
  // Uniaxial stress: strain (1, -nu, -nu) gives stress (E, 0, 0).
  Vector6d e;
  e << 1, -0.3, -0.3, 0, 0, 0;
  const Vector6d s = D * e;
  EXPECT_NEAR(s(0), 10.0, 1e-12);
  EXPECT_NEAR(s(1), 0.0, 1e-12);
  EXPECT_NEAR(D(3, 3), 10.0 / 2.6, 1e-12);
}
