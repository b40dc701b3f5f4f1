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

/// The structured disc of `level` (sectors × rings × layers).
TetMesh mesh_structured_level(const std::string& level, const StructuredDiscOptions& options,
                              const std::string& data_dir,
                              DiscPlacement placement = DiscPlacement::spine);

}  // namespace spinesim::mesh
