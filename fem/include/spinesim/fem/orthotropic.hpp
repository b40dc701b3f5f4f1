// Orthotropic elasticity in engineering constants, and the orthotropic form of a fibre-reinforced
// tet (what solvers with an "orthotropic elastic" material and local axes take: FEBio).
//
// A tet with two fibre families of equal stiffness k and unit directions a1, a2 has the Voigt
// elasticity D = D_iso + k (m1 m1^T + m2 m2^T) (fibres.hpp). It is orthotropic about
//   e1 = (a1 + a2)/|a1 + a2|,  e2 = (a1 - a2)/|a1 - a2|,  e3 = e1 x e2:
// a1 = c e1 + s e2 and a2 = c e1 - s e2, so the reflection e2 -> -e2 swaps the families, the
// reflection e1 -> -e1 maps them to -a2 and -a1 (the fibre energy is even in a), and neither
// has an e3 part; D_iso is invariant under all three. With one family (or a1 = ±a2) the tensor is
// transversely isotropic about a1, and any e2 normal to it does.
//
// Engineering constants in the local axes (the Abaqus and FEBio convention): S = D^-1 in the
// local Voigt order (11, 22, 33, 23, 31, 12; engineering shears),
//   E_i = 1/S_ii,  G23 = 1/S_44, G31 = 1/S_55, G12 = 1/S_66,
//   v12 = -S_21 E1 (contraction along 2 under a stress along 1), v23 = -S_32 E2, v31 = -S_13 E3.
#pragma once

#include "spinesim/fem/elasticity.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

struct OrthotropicConstants {
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< columns e1, e2, e3 (right-handed)
  double E1 = 0, E2 = 0, E3 = 0;                       ///< MPa
  double G12 = 0, G23 = 0, G31 = 0;                    ///< MPa
  double v12 = 0, v23 = 0, v31 = 0;
};

/// D (global Voigt order xx, yy, zz, yz, xz, xy) expressed in the frame `axes` (columns: the
/// local axes in global coordinates): D_local = T D T^T for the Voigt strain rotation.
Matrix6d rotate_elasticity(const Matrix6d& D, const Eigen::Matrix3d& axes);

/// The local axes of two fibre directions (header comment); a1 alone (a2 = ±a1 or zero): e1 = a1.
Eigen::Matrix3d fibre_pair_axes(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2);

/// The engineering constants of D in `axes`. Throws std::invalid_argument when D is not
/// orthotropic there (a normal–shear or shear–shear coupling above 1e-9 of the largest term)
/// or not positive definite.
OrthotropicConstants orthotropic_constants(const Matrix6d& D, const Eigen::Matrix3d& axes);

/// The global Voigt elasticity of the constants (the inverse of orthotropic_constants).
Matrix6d orthotropic_elasticity(const OrthotropicConstants& c);

}  // namespace spinesim::fem
