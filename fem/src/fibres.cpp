#include "spinesim/fem/fibres.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/fem/fe_space.hpp"

#include <cmath>
#include <limits>

namespace spinesim::fem {

namespace {

// K_ab += k (\int h_a h_b dV) a a^T,  h = grad N . a, with the exact 4-point degree-2 rule
// (P2: h is linear, the integrand quadratic; P1: h constant).
template <int NPE>
void add_family(const TetVertices& X, const Eigen::Vector3d& a, double k,
                Eigen::Matrix<double, 3 * NPE, 3 * NPE>& Ke) {
  static const double qa = 0.5854101966249685, qb = 0.1381966011250105;
  double vol = 0;
  const Eigen::Matrix<double, 4, 3> gL = barycentric_gradients(X, vol);
  Eigen::Matrix<double, NPE, NPE> H = Eigen::Matrix<double, NPE, NPE>::Zero();
  const int nq = NPE == 4 ? 1 : 4;
  for (int q = 0; q < nq; ++q) {
    Eigen::Vector4d L = Eigen::Vector4d::Constant(qb);
    L(q) = qa;
    const Eigen::MatrixX3d G = shape_gradients(NPE == 4 ? 1 : 2, gL, L);
    const Eigen::Matrix<double, NPE, 1> h = G * a;
    H.noalias() += (vol / nq) * h * h.transpose();
  }
  const Eigen::Matrix3d aa = k * a * a.transpose();
  for (int i = 0; i < NPE; ++i)
    for (int j = 0; j < NPE; ++j) Ke.template block<3, 3>(3 * i, 3 * j) += H(i, j) * aa;
}

}  // namespace

Matrix6d fibre_elasticity(const Eigen::Vector3d& a, double k) {
  Vector6d m;
  m << a.x() * a.x(), a.y() * a.y(), a.z() * a.z(), a.y() * a.z(), a.x() * a.z(), a.x() * a.y();
  return k * m * m.transpose();
}

void add_fibre_stiffness(const TetVertices& X, const Eigen::Vector3d& a, double k,
                         Eigen::Matrix<double, 12, 12>& Ke) {
  add_family<4>(X, a, k, Ke);
}

void add_fibre_stiffness(const TetVertices& X, const Eigen::Vector3d& a, double k,
                         Eigen::Matrix<double, 30, 30>& Ke) {
  add_family<10>(X, a, k, Ke);
}

}  // namespace spinesim::fem
