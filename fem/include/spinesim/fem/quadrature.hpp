// Quadrature rules on the reference tetrahedron, in barycentric coordinates.
//
// Weights sum to 1 (multiply by the tet volume). Two rules:
//   - tet_rule_degree2(): the symmetric 4-point rule, exact for polynomials of degree <= 2
//     (so exact for the P2 stiffness on straight tets, whose integrand is quadratic);
//   - tet_rule_collapsed(n): the conical (Duffy) product of n-point Gauss–Legendre rules,
//     n^3 points, exact for degree <= 2n-3 — used for load vectors of smooth body forces
//     and for L² errors (Stroud, "Approximate calculation of multiple integrals", 1971).
#pragma once

#include <Eigen/Core>

namespace spinesim::fem {

struct TetQuadrature {
  Eigen::MatrixX4d barycentric;  ///< #q×4 barycentric coordinates (L0..L3) of the points
  Eigen::VectorXd weights;       ///< #q weights, summing to 1
};

TetQuadrature tet_rule_degree2();

/// The rule of the nonlinear elements of an order (hyperelastic_element.hpp, nonlinear_fields.hpp):
/// one point (the centroid) for P1, the symmetric 4-point rule for P2, as CalculiX's C3D4/C3D10.
const TetQuadrature& element_rule(int order);

/// n >= 1 Gauss points per direction; throws std::invalid_argument for n < 1 or n > 10.
TetQuadrature tet_rule_collapsed(int n);

}  // namespace spinesim::fem
