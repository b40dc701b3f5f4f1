// The annulus-like material of the nonlinear tests: a soft neo-Hookean matrix (C10 0.35 MPa,
// D1 0.3 /MPa) and two tension-only families at ±30° from `circumferential` towards `axial`
// (k1 3 MPa, k2 45).
#pragma once

#include "spinesim/fem/hyperelastic.hpp"

#include <cmath>

namespace spinesim::fem::fixtures {

inline FibreHyperelastic annulus(const Eigen::Vector3d& circumferential = Eigen::Vector3d::UnitX(),
                                 const Eigen::Vector3d& axial = Eigen::Vector3d::UnitY()) {
  FibreHyperelastic m;
  m.c10_mpa = 0.35;
  m.d1_per_mpa = 0.3;
  const double a = 30.0 * M_PI / 180.0;
  const Eigen::Vector3d c = circumferential.normalized(), z = axial.normalized();
  m.fibres.push_back({(std::cos(a) * c + std::sin(a) * z).normalized(), 3.0, 45.0});
  m.fibres.push_back({(std::cos(a) * c - std::sin(a) * z).normalized(), 3.0, 45.0});
  return m;
}

/// A plate motion (mm, rad) that strains a test disc's annulus well beyond the linear range.
inline Eigen::Matrix<double, 6, 1> flexion_and_compression() {
  Eigen::Matrix<double, 6, 1> q;
  q << 0.02, -0.4, 0.05, 0.04, -0.01, 0.02;
  return q;
}

/// #nodes×3 displacements as a body's node-major vector.
inline Eigen::VectorXd flat(const Eigen::MatrixX3d& d) {
  Eigen::VectorXd u(3 * d.rows());
  for (Eigen::Index n = 0; n < d.rows(); ++n) u.segment<3>(3 * n) = d.row(n).transpose();
  return u;
}

}  // namespace spinesim::fem::fixtures
