// A disc level meshed: the parametric disc of T1-T2 … L5-S1 (morphometry from
// <data_dir>/disc_morphometry.csv), meshed by CGAL Mesh_3 or as the structured haptic-resolution
// disc, and placed between its vertebrae in the spine frame (thesis F.1/F.2) or upright at the
// origin.
#pragma once

#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <string>

namespace spinesim::mesh {

/// Where a meshed level sits: between its vertebrae in the spine frame, or upright at the origin.
enum class DiscPlacement { spine, local };

/// The frame of `level` for `placement` (identity for local). Throws std::invalid_argument for
/// an unknown level.
DiscFrame disc_level_frame(const std::string& level, const std::string& data_dir,
                           DiscPlacement placement = DiscPlacement::spine);

/// The parametric disc of `level` meshed with `options`.
TetMesh mesh_disc_level(const std::string& level, const MeshOptions& options,
                        const std::string& data_dir,
                        DiscPlacement placement = DiscPlacement::spine);

/// The same with default options and the cell size given, mm.
TetMesh mesh_disc_level(const std::string& level, double cell_size_mm, const std::string& data_dir);

/// A rigid motion x ↦ R x + t (mm).
struct RigidMotion {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return R * x + t; }
};

/// Carries a disc meshed at `frame` (its local y from −h/2 at the lower endplate to +h/2 at the
/// upper one) along with its two vertebrae: each node moves to (1 − s)·lower(x) + s·upper(x), s
/// its height fraction (local y + h/2)/h clamped to [0, 1]. The endplates move rigidly with their
/// vertebrae and the wall follows linearly: for two vertebrae of a scoliotic curve, the wedged
/// and twisted disc between them. The mesh's frame goes with it: its origin midway between the
/// two vertebrae's images of the old one, its axes turned halfway from the lower rotation to the
/// upper. Throws std::invalid_argument (one line) if a tet would invert.
void carry_between(TetMesh& m, const DiscFrame& frame, double height_mm, const RigidMotion& lower,
                   const RigidMotion& upper);

/// The structured disc of `level` (sectors × rings × layers).
TetMesh mesh_structured_level(const std::string& level, const StructuredDiscOptions& options,
                              const std::string& data_dir,
                              DiscPlacement placement = DiscPlacement::spine);

}  // namespace spinesim::mesh
