// Stress, strain and energy fields of a linear FEM solution, one value per tet.
//
// Every field is the tet's volume mean. On straight P1/P2 tets strain, stress and the mixed
// formulation's mean stress p are constant or linear, so their mean is their value at the
// centroid (what CalculiX's C3D4 reports at its one integration point, and the mean of its
// C3D10's four); the quadratic strain energy density is averaged with the degree-2 rule.
//
//   strain              eps = sym grad u (tensor components, not engineering shears)
//   stress              displacement form: D_iso eps + sum_f k_f (a_f . eps a_f) a_f (x) a_f;
//                       mixed form (mixed.hpp): 2 mu dev eps + p I + the same fibre terms
//   von Mises           sqrt(3/2 s : s), s = dev stress
//   pressure            -tr(stress)/3, positive in compression
//   principal strains   eigenvalues of eps, e1 >= e2 >= e3, with unit eigenvectors (each
//                       signed so that its largest-magnitude component is positive)
//   fibre stretch       1 + a_f . eps a_f per family (the small-strain stretch); 0 in a tet
//                       without fibres
//   fibre stress        k_f (a_f . eps a_f), MPa, per family (tension > 0); 0 without fibres
//   energy density      displacement form: 1/2 eps : stress; mixed form: mu |dev eps|^2 +
//                       p^2 / (2 kappa) + the fibre energy — the energy the mixed system stores,
//                       so that sum_t W_t V_t = 1/2 q^T K6 q in both forms. MPa = mJ/mm^3.
// Symmetric tensors are stored as 6 components in ParaView's order (xx, yy, zz, xy, yz, xz), so
// ParaView's tensor filters read them as they are.
#pragma once

#include "spinesim/fem/fibres.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::fem {

/// Per-tet fields (#T rows each), units in the names.
struct ElementFields {
  Eigen::MatrixXd strain;                        ///< #T×6 (xx, yy, zz, xy, yz, xz), 1
  Eigen::MatrixXd stress_mpa;                    ///< #T×6 same order, MPa
  Eigen::VectorXd von_mises_mpa;                 ///< #T
  Eigen::VectorXd pressure_mpa;                  ///< #T, -tr(stress)/3
  Eigen::MatrixX3d principal_strain;             ///< #T×3, descending
  Eigen::MatrixXd principal_strain_directions;   ///< #T×9: unit e1, e2, e3
  Eigen::MatrixX2d fibre_stretch;                ///< #T×2, families 1 and 2 (0: no fibres)
  Eigen::MatrixX2d fibre_stress_mpa;             ///< #T×2 (0: no fibres)
  Eigen::VectorXd strain_energy_density_mpa;     ///< #T, mJ/mm^3
};

/// The fields of the solution with displacements `node_displacement_mm` (#nodes×3 on the
/// order-`order` node set of `mesh`, fe_space.hpp) and material `materials` with fibre field
/// `fibres` (may be empty). For the mixed formulation pass `mean_stress_mpa` (#T×4: p at each
/// tet's vertices for the tet's region, tension > 0); the displacement form passes nullptr.
/// Throws std::invalid_argument when the sizes do not match the mesh.
ElementFields element_fields(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                             const ElementFibres& fibres, int order,
                             const Eigen::MatrixX3d& node_displacement_mm,
                             const Eigen::MatrixX4d* mean_stress_mpa = nullptr);

/// Von Mises stress (MPa) of a stress stored in the order above (xx, yy, zz, xy, yz, xz).
double von_mises(const Eigen::Matrix<double, 6, 1>& s);

/// Eigenvalues of the symmetric `eps`, descending, and their unit eigenvectors as columns, each
/// signed so that its largest-magnitude component is positive.
void principal(const Eigen::Matrix3d& eps, Eigen::Vector3d& values, Eigen::Matrix3d& directions);

}  // namespace spinesim::fem
