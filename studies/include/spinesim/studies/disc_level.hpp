// A disc level meshed for a study: the parametric disc of T1-T2 … L5-S1 (morphometry from
// data/disc_morphometry.csv), meshed by CGAL Mesh_3 or as the structured haptic-resolution disc,
// and placed between its vertebrae in the spine frame (thesis F.1/F.2) or upright at the origin.
#pragma once

#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <string>

namespace spinesim::studies {

/// Where a meshed level sits: between its vertebrae in the spine frame, or upright at the origin.
enum class DiscPlacement { spine, local };

/// The frame of `level` for `placement` (identity for local). Throws std::invalid_argument for
/// an unknown level.
mesh::DiscFrame disc_level_frame(const std::string& level,
                                 DiscPlacement placement = DiscPlacement::spine);

/// The parametric disc of `level` meshed with `options`.
mesh::TetMesh mesh_disc_level(const std::string& level, const mesh::MeshOptions& options,
                              DiscPlacement placement = DiscPlacement::spine);

/// The same with default options and the cell size given, mm.
mesh::TetMesh mesh_disc_level(const std::string& level, double cell_size_mm);

/// The structured disc of `level` (sectors × rings × layers).
mesh::TetMesh mesh_structured_level(const std::string& level,
                                    const mesh::StructuredDiscOptions& options,
                                    DiscPlacement placement = DiscPlacement::spine);

}  // namespace spinesim::studies
