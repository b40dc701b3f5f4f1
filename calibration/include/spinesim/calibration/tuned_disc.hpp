// The tuned-disc parameter file (tuned.json) that `spinesim calibrate` writes and `spinesim mss`,
// `mss compare`, the spine scene and the haptic loop load.
//
// What it holds: the MSS terms that were on and their factors, one stiffness scale per knob
// (linear_mss.hpp, e.g. "torsion.nucleus": 0.31), what the scales belong to — disc level,
// material (name and every region's E, nu, rho), the mesh they were fitted on (counts and a
// fingerprint) — and the calibration's report (cases with untuned and tuned errors, 6×6
// diagonals, Ipopt's status), kept verbatim under "report".
//
// Two kinds (the "kind" field; format version 1 for both — a reader that knows only region-level
// files refuses a per-spring one by its kind):
//   "region"      per-region scales only. They are properties of a disc and its material, not of
//                 one mesh: they apply to any mesh of the same level (a coarse haptic mesh, a
//                 fine study mesh) with the same material.
//   "per-spring"  the region scales plus one multiplier per main (edge) spring
//                 ("edge_multipliers", the mesh's edge order; per_spring.hpp). They belong to the
//                 mesh they were fitted on and apply to no other.
// Loading checks that: a different material, a mesh of another level, or — for a per-spring
// file — any mesh with another fingerprint is refused with a one-line message; a mesh whose
// level is unknown (e.g. meshed from vertebra surfaces) is accepted for a region-level file, and
// the caller is told so (`check_applies`'s note).
#pragma once

#include "spinesim/calibration/linear_mss.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace spinesim::calibration {

/// Mesh identity: vertex and tet counts and a 64-bit FNV-1a hash of the connectivity, labels
/// and coordinates (rounded to 1 nm), as 16 hex digits.
struct MeshFingerprint {
  Eigen::Index nodes = 0, tets = 0;
  std::string hash;
  bool operator==(const MeshFingerprint& o) const {
    return nodes == o.nodes && tets == o.tets && hash == o.hash;
  }
};
MeshFingerprint fingerprint(const mesh::TetMesh& mesh);

/// The disc level a mesh was built for ("L4-L5"), read from its provenance as spinesim's
/// builders write it ("parametric disc L4-L5", "structured disc T12-L1 (...)"); empty if
/// unknown — also when `source` is only the file a foreign mesh was read from, whose name says
/// nothing reliable about the level.
std::string disc_level(const mesh::TetMesh& mesh);

/// Every region's (E MPa, nu, rho kg/m^3) as JSON: {"annulus": {...}, "nucleus": {...}}.
nlohmann::json material_signature(const mesh::RegionMaterials& materials);

struct TunedDisc {
  std::string level;  ///< "" when the mesh's level was unknown
  std::string material_name;
  nlohmann::json material;  ///< material_signature
  MeshFingerprint mesh;     ///< the mesh the scales were fitted on
  int fem_order = 2;
  mss::MssOptions options;               ///< terms on/off and factors; scales filled from `scales`
  std::map<std::string, double> scales;  ///< knob name -> scale (> 0)
  /// Kind "per-spring": one multiplier mu_e > 0 per edge spring of the fitted mesh, in the
  /// model's edge order; empty for a region-level file.
  std::vector<double> edge_multipliers;
  /// Kind "per-spring": edge_order_hash() of the model the multipliers were fitted on, so a
  /// change of the MSS's edge ordering can never put them on the wrong springs silently.
  std::string edge_order;
  nlohmann::json report;  ///< the calibration's summary (free form)

  bool per_spring() const { return !edge_multipliers.empty(); }
  /// "region" or "per-spring".
  std::string kind() const { return per_spring() ? "per-spring" : "region"; }

  /// `options` with its scales set from `scales` (knobs not listed stay 1) and the per-spring
  /// multipliers (if any).
  mss::MssOptions mss_options() const;
  /// The material the scales were fitted with, rebuilt from `material_name` and `material`
  /// (so a file calibrated with a material JSON file loads without it).
  mesh::RegionMaterials materials() const;
};

/// 64-bit FNV-1a hash (16 hex digits) of a model's edge springs' end nodes, in its edge order.
std::string edge_order_hash(const mss::MssModel& model);

/// The MSS of `mesh` with the tuned options, after check_applies; for a per-spring file also
/// checks that the model orders its springs as the fitted one did (std::invalid_argument).
mss::MssModel build_tuned_model(const TunedDisc& tuned, const mesh::TetMesh& mesh,
                                const mesh::RegionMaterials& materials);

/// Which terms `options` switch on and their factors, as tuned files ("terms") and the MSS
/// reports write them.
nlohmann::json terms_json(const mss::MssOptions& options);

nlohmann::json to_json(const TunedDisc& t);
/// Parses and validates (format tag, version, kind, positive finite scales, known knob names,
/// terms of every scale switched on, positive finite term factors, a valid material per region,
/// fem_order 1 or 2; per-spring: a non-empty array of positive finite multipliers, matching
/// "edge_springs"); throws std::invalid_argument with a one-line message.
TunedDisc tuned_disc_from_json(const nlohmann::json& j);
/// Reads a tuned.json; throws std::invalid_argument naming the file for unreadable or invalid
/// content.
TunedDisc read_tuned_disc(const std::string& path);

/// Throws std::invalid_argument (one line) unless `tuned` applies to `mesh` with `materials`:
/// same material (name and E, nu per region), same level when both levels are known, and for a
/// per-spring file the very mesh it was fitted on (same fingerprint). Returns a
/// note for the user when the level could not be checked ("mesh level unknown: ...") — not for
/// the very mesh the scales were fitted on (same fingerprint) — and "" otherwise.
std::string check_applies(const TunedDisc& tuned, const mesh::TetMesh& mesh,
                          const mesh::RegionMaterials& materials);

}  // namespace spinesim::calibration
