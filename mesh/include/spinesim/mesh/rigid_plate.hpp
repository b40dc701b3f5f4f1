// The rigid superior plate of the disc problem, shared by the FEM, the mass-spring disc, the
// calibration and the studies (one definition, so the three agree by construction).
//
// The plate moves by q = (t mm, theta rad) about its centre c. To first order (small rotation),
// a point at rest position X moves by
//     u = t + theta × (X − c) = R(X − c) q,    R(r) = [ I | −[r]× ]   (3×6),
// where [r]× is the cross-product matrix (theta × r = −[r]× theta). The exact rigid pose of a
// finite rotation is mss::plate_pose; the FEM and every linearisation use R.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::mesh {

using PlateMap = Eigen::Matrix<double, 3, 6>;

/// R(r) for the arm r = X − c (mm): R q = t + theta × r.
PlateMap plate_map(const Eigen::Vector3d& arm_mm);

/// RMS over the superior-endplate vertices (surface label 2) of |t + theta × (X_i − c)|, mm:
/// the size of a plate motion q in one length that weighs rotations by the plate's extent.
/// 0 when the mesh has no superior-endplate vertex.
double plate_rms_displacement(const TetMesh& m, const Eigen::Vector3d& center_mm,
                              const Eigen::Matrix<double, 6, 1>& q);

/// RMS distance of the superior-endplate vertices from the centre, mm (1 when there are none,
/// so that it can divide a moment).
double plate_rms_radius(const TetMesh& m, const Eigen::Vector3d& center_mm);

}  // namespace spinesim::mesh
