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

}  // namespace spinesim::fem::fixtures
