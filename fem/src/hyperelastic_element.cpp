#include "spinesim/fem/hyperelastic_element.hpp"

#include "spinesim/fem/quadrature.hpp"

#include <Eigen/LU>

#include <limits>
#include <stdexcept>

namespace spinesim::fem {

namespace {

/// B_a (6×3) of one node at deformation gradient F, gradient g = ∇N_a.
Eigen::Matrix<double, 6, 3> strain_displacement(const Eigen::Matrix3d& F,
                                                const Eigen::Vector3d& g) {
  Eigen::Matrix<double, 6, 3> B;
  for (int i = 0; i < 3; ++i) {
    B(0, i) = F(i, 0) * g(0);
    B(1, i) = F(i, 1) * g(1);
    B(2, i) = F(i, 2) * g(2);
    B(3, i) = F(i, 1) * g(2) + F(i, 2) * g(1);
    B(4, i) = F(i, 0) * g(2) + F(i, 2) * g(0);
    B(5, i) = F(i, 0) * g(1) + F(i, 1) * g(0);
  }
  return B;
}

}  // namespace

HyperelasticElement hyperelastic_element(int order, const TetVertices& X, const Eigen::MatrixX3d& u,
                                         const FibreHyperelastic& m, bool with_tangent) {
  if (order != 1 && order != 2) throw std::invalid_argument("element order must be 1 or 2");
  const int npe = order == 1 ? 4 : 10;
  if (u.rows() != npe) throw std::invalid_argument("element displacements: wrong node count");
  double volume = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, volume);
  static const TetQuadrature p1 = [] {
    TetQuadrature q;
    q.barycentric = Eigen::RowVector4d::Constant(0.25);
    q.weights = Eigen::VectorXd::Ones(1);
    return q;
  }();
  static const TetQuadrature p2 = tet_rule_degree2();
  const TetQuadrature& rule = order == 1 ? p1 : p2;

  HyperelasticElement out;
  out.force = Eigen::VectorXd::Zero(3 * npe);
  if (with_tangent) out.tangent = Eigen::MatrixXd::Zero(3 * npe, 3 * npe);
  std::vector<Eigen::Matrix<double, 6, 3>> B(static_cast<std::size_t>(npe));
  for (Eigen::Index q = 0; q < rule.weights.size(); ++q) {
    const Eigen::Vector4d L = rule.barycentric.row(q).transpose();
    const Eigen::MatrixX3d G = shape_gradients(order, gL, L);
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + u.transpose() * G;
    const double dV = rule.weights(q) * volume;
    if (!(F.determinant() > 0)) {
      ++out.inverted_points;
      out.energy = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const MaterialPointState p = fibre_hyperelastic_point(F.transpose() * F, m, with_tangent);
    out.energy += dV * p.energy;
    const Vector6d S = to_voigt(p.S);
    for (int a = 0; a < npe; ++a) {
      B[std::size_t(a)] = strain_displacement(F, G.row(a).transpose());
      out.force.segment<3>(3 * a) += dV * B[std::size_t(a)].transpose() * S;
    }
    if (!with_tangent) continue;
    for (int a = 0; a < npe; ++a) {
      const Eigen::Matrix<double, 3, 6> BaC = B[std::size_t(a)].transpose() * p.tangent;
      const Eigen::RowVector3d gSa = G.row(a) * p.S;
      for (int b = 0; b <= a; ++b) {
        Eigen::Matrix3d k = BaC * B[std::size_t(b)];
        k.diagonal().array() += gSa.dot(G.row(b));
        out.tangent.block<3, 3>(3 * a, 3 * b) += dV * k;
        if (b != a) out.tangent.block<3, 3>(3 * b, 3 * a) += dV * k.transpose();
      }
    }
  }
  return out;
}

}  // namespace spinesim::fem
