// `spinesim mesh disc` as a driver: a disc meshed from a parametric level (CGAL Mesh_3 or the
// structured sweep) or between two vertebra surfaces, its quality against the exact volume, and
// the VTU (with an optional Medit copy) written both or neither.
#pragma once

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/spine/model.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::studies {

struct MeshDiscRequest {
  std::string level;               ///< a parametric level T1-T2 … L5-S1, or
  std::string inferior, superior;  ///< two vertebra (or endplate) surface files
  double surface_mm_per_unit = 1;  ///< the surface files' length unit, mm
  mesh::UpAxis up = mesh::UpAxis::y;
  mesh::DiscPlacement placement = mesh::DiscPlacement::spine;  ///< of a parametric level
  bool structured = false;                                     ///< the structured sweep, not CGAL
  mesh::StructuredDiscOptions structured_options;
  mesh::MeshOptions cgal;
  /// A parametric level of a scoliotic spine (cobb_deg 0: straight): the disc is carried between
  /// its two vertebrae in the curve's rest posture (mesh::carry_between), wedged and twisted as
  /// the curve has them; placed in the curved spine, or (local) in its lower vertebra's frame.
  spine::ScoliosisCurve scoliosis;
  /// A parametric level of another body's spine (zeros: the reference body): the disc is the
  /// reference disc scaled by height / 1.778 m (geometric similarity, as the spine is); CGAL's
  /// sizes stay the asked ones in millimetres.
  spine::Subject subject;
  std::string out, medit;  ///< the VTU (empty: nothing written), and an optional Medit copy
};

struct MeshDiscResult {
  MeshDiscRequest request;
  mesh::TetMesh mesh;
  mesh::QualityReport quality;
  double mesh_seconds = 0;
  nlohmann::json disc;  ///< between vertebrae: the footprint, heights and filled holes
  std::string warning;  ///< one line for the user (endplate holes filled), or empty
};

/// Checks the request (one of level and the two surfaces; the outputs writable) before any
/// work, meshes, reports quality and writes the files. Stages: reading the surfaces (between
/// vertebrae only), meshing, writing. Throws std::invalid_argument (one line) for bad input.
MeshDiscResult run_mesh_disc(const MeshDiscRequest& request, const std::string& data_dir,
                             const StageHooks& hooks = StageHooks());

/// The stages run_mesh_disc reports for `request` (for a numbered progress display).
int mesh_disc_stages(const MeshDiscRequest& request);

/// Quality, timings, outputs, the options the mesh was made with and what it was made from.
nlohmann::json mesh_disc_json(const MeshDiscResult& r);

}  // namespace spinesim::studies
