// The lamella frame of every annulus tet, from the disc's own geometry: where the tet sits
// between the nucleus and the outer wall, and which way the outline runs there. Fibre-reinforced
// annulus materials orient their fibres in it.
//
// For a tet of region 1 (annulus) with centroid c:
//   - d_o, n_o: distance to the nearest outer-wall face and that face's outward normal;
//   - d_i, n_i: distance to the nearest annulus–nucleus interface face and its normal (pointing
//     out of the nucleus);
//   - depth s = d_i / (d_i + d_o): 0 at the nucleus, 1 at the outer wall (without a nucleus,
//     s = 1 - d_o / max d_o over the annulus);
//   - radial direction: (1 - s) n_i + s n_o with its axial part removed, normalised;
//   - circumferential direction: axial × radial (anticlockwise seen from above), unit;
//   - axial direction: the disc frame's y axis (mesh.frame.axes.col(1)).
// Outer-wall faces are the boundary faces not lying wholly on one endplate (surface labels
// 1 or 2 on all three vertices). Tets of other regions get depth NaN and zero directions.
// Closest points come from CGAL AABB trees (kept out of this header).
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace spinesim::mesh {

struct AnnulusFrames {
  Eigen::MatrixX3d circumferential;  ///< #T×3 unit tangent of the outline (zero outside)
  Eigen::MatrixX3d radial;           ///< #T×3 unit, outward, transverse (zero outside)
  Eigen::MatrixX3d axial;            ///< #T×3 unit disc axis (zero outside)
  Eigen::VectorXd depth;             ///< #T, in [0, 1] in the annulus, NaN outside
};

/// Throws std::invalid_argument when the mesh has annulus tets but no outer-wall face.
AnnulusFrames annulus_frames(const TetMesh& m);

}  // namespace spinesim::mesh
