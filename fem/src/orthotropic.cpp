// Orthotropic engineering constants and the fibre-pair axes; see orthotropic.hpp.
#include "spinesim/fem/orthotropic.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace spinesim::fem {
namespace {

/// Voigt index of the tensor pair (i, j) in our order xx, yy, zz, yz, xz, xy.
int voigt(int i, int j) {
  static const int table[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
  return table[i][j];
}

}  // namespace

Matrix6d rotate_elasticity(const Matrix6d& D, const Eigen::Matrix3d& axes) {
  // C'_ijkl = Q_pi Q_qj Q_rk Q_sl C_pqrs with Q = axes (local axis i is column i). The Voigt
  // matrix of engineering strains holds the tensor components themselves (C_ijkl = D(IJ, KL)).
  Matrix6d out = Matrix6d::Zero();
  const Eigen::Matrix3d& Q = axes;
  static const int pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  for (int I = 0; I < 6; ++I)
    for (int J = 0; J < 6; ++J) {
      const int i = pairs[I][0], j = pairs[I][1], k = pairs[J][0], l = pairs[J][1];
      double sum = 0;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          for (int r = 0; r < 3; ++r)
            for (int s = 0; s < 3; ++s)
              sum += Q(p, i) * Q(q, j) * Q(r, k) * Q(s, l) * D(voigt(p, q), voigt(r, s));
      out(I, J) = sum;
    }
  return out;
}

Eigen::Matrix3d fibre_pair_axes(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2) {
  Eigen::Vector3d e1 = a1 + a2, e2 = a1 - a2;
  const double scale = std::max(a1.norm(), a2.norm());
  if (!(scale > 0)) throw std::invalid_argument("fibre_pair_axes: no fibre direction");
  if (e1.norm() < 1e-9 * scale) e1 = a1;       // a2 = -a1: one family
  else if (e2.norm() < 1e-9 * scale) e2 = Eigen::Vector3d::Zero();  // a2 = a1
  e1.normalize();
  e2 -= e1.dot(e2) * e1;
  if (e2.norm() < 1e-9) {  // one family: any e2 normal to e1
    const int k = std::abs(e1.x()) < 0.9 ? 0 : 1;
    e2 = e1.cross(Eigen::Vector3d::Unit(k));
  }
  e2.normalize();
  Eigen::Matrix3d axes;
  axes << e1, e2, e1.cross(e2);
  return axes;
}

OrthotropicConstants orthotropic_constants(const Matrix6d& D, const Eigen::Matrix3d& axes) {
  const Matrix6d L = rotate_elasticity(D, axes);
  const double scale = L.cwiseAbs().maxCoeff();
  // Orthotropic: no coupling between normal and shear strains, nor between two shears.
  for (int I = 0; I < 6; ++I)
    for (int J = 0; J < 6; ++J) {
      const bool coupled = (I < 3) != (J < 3) || (I >= 3 && J >= 3 && I != J);
      if (coupled && std::abs(L(I, J)) > 1e-9 * scale)
        throw std::invalid_argument("orthotropic_constants: the elasticity is not orthotropic "
                                    "in the given axes");
    }
  if (Eigen::LLT<Matrix6d>(L).info() != Eigen::Success)
    throw std::invalid_argument("orthotropic_constants: the elasticity is not positive definite");
  const Matrix6d S = L.inverse();
  OrthotropicConstants c;
  c.axes = axes;
  c.E1 = 1 / S(0, 0);
  c.E2 = 1 / S(1, 1);
  c.E3 = 1 / S(2, 2);
  c.G23 = 1 / S(3, 3);
  c.G31 = 1 / S(4, 4);
  c.G12 = 1 / S(5, 5);
  c.v12 = -S(1, 0) * c.E1;
  c.v23 = -S(2, 1) * c.E2;
  c.v31 = -S(0, 2) * c.E3;
  return c;
}

Matrix6d orthotropic_elasticity(const OrthotropicConstants& c) {
  Matrix6d S = Matrix6d::Zero();
  S(0, 0) = 1 / c.E1;
  S(1, 1) = 1 / c.E2;
  S(2, 2) = 1 / c.E3;
  S(1, 0) = S(0, 1) = -c.v12 / c.E1;
  S(2, 1) = S(1, 2) = -c.v23 / c.E2;
  S(0, 2) = S(2, 0) = -c.v31 / c.E3;
  S(3, 3) = 1 / c.G23;
  S(4, 4) = 1 / c.G31;
  S(5, 5) = 1 / c.G12;
  // Local to global: rotate by the transpose (the global axes seen from the local frame).
  return rotate_elasticity(S.inverse(), c.axes.transpose());
}

}  // namespace spinesim::fem
