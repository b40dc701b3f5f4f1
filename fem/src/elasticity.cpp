#include "spinesim/fem/elasticity.hpp"

#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/quadrature.hpp"

#include <Eigen/LU>

#include <stdexcept>

namespace spinesim::fem {

Matrix6d isotropic_elasticity(const mesh::IsotropicMaterial& m) {
  const double lambda = m.lame_lambda_mpa(), mu = m.shear_modulus_mpa();
  Matrix6d D = Matrix6d::Zero();
  D.topLeftCorner<3, 3>().setConstant(lambda);
  for (int i = 0; i < 3; ++i) {
    D(i, i) = lambda + 2 * mu;
    D(3 + i, 3 + i) = mu;
  }
  return D;
}

Eigen::Matrix<double, 4, 3> barycentric_gradients(const TetVertices& X, double& volume_mm3) {
  Eigen::Matrix3d J;  // columns: edges from vertex 0
  J.col(0) = (X.row(1) - X.row(0)).transpose();
  J.col(1) = (X.row(2) - X.row(0)).transpose();
  J.col(2) = (X.row(3) - X.row(0)).transpose();
  volume_mm3 = J.determinant() / 6.0;
  const Eigen::Matrix3d Jinv = J.inverse();  // rows are grad L1..L3
  Eigen::Matrix<double, 4, 3> G;
  G.bottomRows<3>() = Jinv;
  G.row(0) = -Jinv.colwise().sum();
  return G;
}

Eigen::VectorXd shape_values(int order, const Eigen::Vector4d& L) {
  if (order == 1) return L;
  Eigen::VectorXd N(10);
  for (int a = 0; a < 4; ++a) N(a) = L(a) * (2 * L(a) - 1);
  for (int e = 0; e < 6; ++e) N(4 + e) = 4 * L(kP2LocalEdges[e][0]) * L(kP2LocalEdges[e][1]);
  return N;
}

Eigen::MatrixX3d shape_gradients(int order, const Eigen::Matrix<double, 4, 3>& gL,
                                 const Eigen::Vector4d& L) {
  if (order == 1) return gL;
  Eigen::MatrixX3d G(10, 3);
  for (int a = 0; a < 4; ++a) G.row(a) = (4 * L(a) - 1) * gL.row(a);
  for (int e = 0; e < 6; ++e) {
    const int a = kP2LocalEdges[e][0], b = kP2LocalEdges[e][1];
    G.row(4 + e) = 4 * (L(b) * gL.row(a) + L(a) * gL.row(b));
  }
  return G;
}

namespace {

// K_ab = lambda S_ab + mu S_ab^T + mu tr(S_ab) I with S_ab = \int g_a g_b^T dV.
template <int N>
void fill_from_gradient_products(const Eigen::Matrix<double, N, 3>* G, const double* w, int nq,
                                 double lambda, double mu,
                                 Eigen::Matrix<double, 3 * N, 3 * N>& Ke) {
  for (int a = 0; a < N; ++a)
    for (int b = 0; b <= a; ++b) {
      Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
      for (int q = 0; q < nq; ++q) S.noalias() += w[q] * G[q].row(a).transpose() * G[q].row(b);
      Eigen::Matrix3d block = lambda * S + mu * S.transpose();
      block.diagonal().array() += mu * S.trace();
      Ke.template block<3, 3>(3 * a, 3 * b) = block;
      if (a != b) Ke.template block<3, 3>(3 * b, 3 * a) = block.transpose();
    }
}

}  // namespace

void element_stiffness_p1(const TetVertices& X, double lambda, double mu,
                          Eigen::Matrix<double, 12, 12>& Ke) {
  double vol = 0;
  const Eigen::Matrix<double, 4, 3> G = barycentric_gradients(X, vol);
  const double w = vol;
  fill_from_gradient_products<4>(&G, &w, 1, lambda, mu, Ke);
}

void element_stiffness_p2(const TetVertices& X, double lambda, double mu,
                          Eigen::Matrix<double, 30, 30>& Ke) {
  // The 4-point degree-2 rule is exact: grad N is linear, the integrand quadratic.
  static const double a = 0.5854101966249685, b = 0.1381966011250105;
  double vol = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, vol);
  Eigen::Matrix<double, 10, 3> G[4];
  double w[4];
  for (int q = 0; q < 4; ++q) {
    Eigen::Vector4d L = Eigen::Vector4d::Constant(b);
    L(q) = a;
    for (int v = 0; v < 4; ++v) G[q].row(v) = (4 * L(v) - 1) * gL.row(v);
    for (int e = 0; e < 6; ++e) {
      const int i = kP2LocalEdges[e][0], j = kP2LocalEdges[e][1];
      G[q].row(4 + e) = 4 * (L(j) * gL.row(i) + L(i) * gL.row(j));
    }
    w[q] = 0.25 * vol;
  }
  fill_from_gradient_products<10>(G, w, 4, lambda, mu, Ke);
}

Eigen::MatrixXd element_stiffness(int order, const TetVertices& X,
                                  const mesh::IsotropicMaterial& m) {
  const double lambda = m.lame_lambda_mpa(), mu = m.shear_modulus_mpa();
  if (order == 1) {
    Eigen::Matrix<double, 12, 12> K;
    element_stiffness_p1(X, lambda, mu, K);
    return K;
  }
  if (order == 2) {
    Eigen::Matrix<double, 30, 30> K;
    element_stiffness_p2(X, lambda, mu, K);
    return K;
  }
  throw std::invalid_argument("element_stiffness: order must be 1 or 2");
}

Vector6d element_stress(int order, const TetVertices& X, const mesh::IsotropicMaterial& m,
                        const Eigen::VectorXd& ue, const Eigen::Vector4d& L) {
  double vol = 0;
  const Eigen::MatrixX3d G = shape_gradients(order, barycentric_gradients(X, vol), L);
  Eigen::Matrix3d grad_u = Eigen::Matrix3d::Zero();  // grad_u(i, j) = d u_i / d x_j
  for (Eigen::Index a = 0; a < G.rows(); ++a) grad_u += ue.segment<3>(3 * a) * G.row(a);
  const Eigen::Matrix3d eps = 0.5 * (grad_u + grad_u.transpose());
  Vector6d e;
  e << eps(0, 0), eps(1, 1), eps(2, 2), 2 * eps(1, 2), 2 * eps(0, 2), 2 * eps(0, 1);
  return isotropic_elasticity(m) * e;
}

}  // namespace spinesim::fem
