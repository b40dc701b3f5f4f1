// The calibration protocol over every disc level of the spine (`spinesim calibrate --level all`):
// each level's parametric disc meshed as `mesh disc --level` does (mesh/disc_level.hpp),
// calibrated by calibrate_disc, checked on a second resolution (1.5x the cell size), gathered into
// one tuned set (tuned_set.hpp) that is only complete when every level succeeded.
#pragma once

#include "spinesim/calibration/nonlinear_protocol.hpp"
#include "spinesim/calibration/protocol.hpp"
#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/structured_disc.hpp"

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::calibration {

/// The protocol's second mesh resolution for a level's parametric disc: the same disc at 1.5x
/// `options`' cell size, with a label naming it.
std::pair<std::string, mesh::TetMesh> coarser_level_mesh(const std::string& level,
                                                         mesh::MeshOptions options,
                                                         const std::string& data_dir,
                                                         const StatusLine& status = StatusLine());

/// How `--level all` sizes each level's cells when no single size is given: min(max_mm, disc
/// height / cells_through_height). The default, min(2 mm, height / 5), gives the thin thoracic
/// discs (4.5-7 mm) five cells through their height (at 2 mm the fitted MSS stays much further
/// off the FEM there: calibration/README.md). The palpated discs' set uses min(4 mm, height / 2.5),
/// near the resolutions the palpation loop can step within its budget.
struct CellSizeRule {
  double max_mm = 2.0;
  double cells_through_height = 5.0;
  double cell_size_mm(double height_mm) const;
  std::string describe() const;  ///< "min(2 mm, disc height / 5)"
};
void validate(const CellSizeRule& rule);  ///< throws std::invalid_argument naming the option

/// The cell size of a level's disc under `rule`.
double default_level_cell_size_mm(const std::string& level, const std::string& data_dir,
                                  const CellSizeRule& rule = CellSizeRule());

/// A level's disc as the protocol meshes it, and its second resolution for the transfer check.
struct LevelMeshes {
  mesh::TetMesh mesh;
  std::vector<std::pair<std::string, mesh::TetMesh>> transfer;  ///< empty unless asked for
};

/// The structured disc of `structured` (second resolution: 4 more sectors) when set, else the
/// CGAL disc at `cell_size_mm` (second resolution: coarser_level_mesh).
LevelMeshes mesh_level(const std::string& level,
                       const std::optional<mesh::StructuredDiscOptions>& structured,
                       double cell_size_mm, bool transfer, const std::string& data_dir,
                       const StatusLine& status = StatusLine());

struct AllLevelsRequest {
  std::string data_dir;                ///< the morphometry's folder (disc_morphometry.csv)
  CalibrationRequest calibration;      ///< per level; its transfer_meshes must be empty
  std::optional<double> cell_size_mm;  ///< every level's; default: by cell_size_rule
  CellSizeRule cell_size_rule;         ///< when cell_size_mm is not set
  bool transfer = true;                ///< check each level on its second resolution
  /// Set: calibrate each level's structured disc of these options (the mesh the spine's offline
  /// discs simulate) instead of the CGAL disc; its second resolution has 4 more sectors.
  std::optional<mesh::StructuredDiscOptions> structured;
  /// Set: each level calibrated against the nonlinear FEM disc by this request
  /// (nonlinear_protocol.hpp) instead of `calibration`, whose cases and transfer are then unused.
  std::optional<NonlinearCalibrationRequest> nonlinear;
  std::vector<std::string> levels;  ///< empty: mesh::disc_levels()
  std::string generated_by;         ///< recorded in the set
};

/// One level's row of the report.
struct LevelCalibration {
  std::string level;
  Eigen::Index tets = 0;
  double cell_size_mm = 0;
  bool success = false;
  std::string status;  ///< Ipopt's status
  int iterations = 0;
  double seconds = 0;
  /// Worst relative displacement error over the training / held-out cases (nonlinear check;
  /// against the nonlinear FEM: over every load level); NaN when there is no such case.
  double train_untuned = 0, train_tuned = 0, holdout_untuned = NAN, holdout_tuned = NAN;
  /// Tuned / FEM stiffness diagonal; NaN against the nonlinear FEM (no rest stiffness compared).
  double k6_ratio_min = 0, k6_ratio_max = 0;
  /// Against the nonlinear FEM: worst reaction error over the training / held-out cases; NaN
  /// otherwise.
  double train_reaction_tuned = NAN, holdout_reaction_tuned = NAN;
};

struct AllLevelsResult {
  TunedSet set;  ///< the successful levels
  std::vector<LevelCalibration> levels;
  /// "T7-T8 (Maximum_Iterations_Exceeded), ..."; empty when every level succeeded.
  std::string failed() const;
};

/// (levels done, "T7-T8: stage") as the calibration proceeds.
using LevelProgress = std::function<void(int done, const std::string& label)>;

/// Throws std::invalid_argument for a bad request (as calibrate_disc, before any meshing).
AllLevelsResult calibrate_all_levels(const mesh::RegionMaterials& materials,
                                     const AllLevelsRequest& request,
                                     const LevelProgress& progress = LevelProgress());

}  // namespace spinesim::calibration
