// The cross-product matrix: skew(a) * b == a.cross(b). The one definition every module uses
// (the rigid plate map, the MSS torsion and boundary terms, the joint stiffness about a point).
#pragma once

#include <Eigen/Core>

namespace spinesim {

/// [a]×, the skew-symmetric matrix with [a]× b = a × b.
template <class Derived>
Eigen::Matrix<typename Derived::Scalar, 3, 3> skew(const Eigen::MatrixBase<Derived>& a) {
  using S = typename Derived::Scalar;
  Eigen::Matrix<S, 3, 3> m;
  m << S(0), -a(2), a(1),  //
      a(2), S(0), -a(0),   //
      -a(1), a(0), S(0);
  return m;
}

}  // namespace spinesim
