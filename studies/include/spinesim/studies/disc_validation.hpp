// The FEM disc against in-vitro tests (`spinesim study disc-validation`): the standard loads on
// the disc's superior plate (fem/load_cases.hpp: 500 N compression, 7.5 N·m flexion, extension,
// lateral bending, torsion; inferior endplate fixed), the disc's stiffness in each — load over
// plate motion in the disc frame (compression kN/mm; moments N·m/deg about the plate centre) —
// and, with the mixed formulation, the nucleus pressure over the mean axial stress
// (p_nucleus / (500 N / A), A = mesh volume / disc height). Each is set beside the published
// range of `data/validation/disc_in_vitro.json` and marked MATCH (inside) or MISS.
// With the nonlinear disc (fem/nonlinear_disc.hpp: tension-only fibres, finite strain, the plate
// loaded by the wrench and free to turn) the stiffness is the secant one at the standard load,
// and every load case's moment–rotation (force–displacement) path is kept, one point per load
// increment. A case that does not converge gives no number, and says why.
// Our disc has no posterior elements and rigid endplates: the targets are disc-alone tests; the
// file's whole-segment rows are printed for scale only.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <limits>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::studies {

struct DiscValidationRow {
  std::string quantity, units;                             ///< e.g. "torsion", "N m/deg"
  double ours = std::numeric_limits<double>::quiet_NaN();  ///< NaN: not computed (see note)
  double low = 0, high = 0;                                ///< the published window
  std::string reported, source;                            ///< as the data file gives them
  std::string preparation;                                 ///< "facets and ligaments removed", ...
  std::string note;                                        ///< why `ours` is missing, if it is
  bool match() const { return ours >= low && ours <= high; }
};

/// One standard load case's path on the nonlinear disc: the load along the case's own component
/// (N or N·m) against the plate motion along it (mm or deg), from the first increment to the full
/// load.
struct DiscLoadPath {
  std::string load_case, load_units, motion_units;
  std::vector<double> load, motion;
};

struct NonlinearDiscOptions {
  int order = 1;                   ///< 1 (nodal-average volume) or 2 (mean dilatation)
  std::optional<double> fibre_k2;  ///< the fibres' toe exponent (>= 0); default the material's
  int load_increments = 10;        ///< points per path (>= 1)
  /// Axial compression (N, >= 0) applied with each moment case, as in-vitro tests under a
  /// preload: the rotation is measured from the state under the preload alone. Both loads grow
  /// together along the path (the end state of a hyperelastic disc does not depend on the
  /// order), so a path's intermediate points are not a moment at constant preload.
  double preload_n = 0;
};

struct DiscValidationResult {
  std::string material, formulation, mesh_label;
  Eigen::Index tets = 0, dofs = 0;
  double disc_height_mm = 0, disc_area_mm2 = 0;
  double nucleus_pressure_mpa = std::numeric_limits<double>::quiet_NaN();  ///< at 500 N
  std::vector<DiscValidationRow> rows;
  nlohmann::json whole_segments;    ///< the file's rows for scale, as read
  std::string source;               ///< the file's overall source
  double solve_s = 0;               ///< assembly, factorisation and the five solves
  std::vector<DiscLoadPath> paths;  ///< nonlinear disc only
};

/// A target's specimen preparation in words ("facets and ligaments removed", ...).
std::string disc_target_preparation(const nlohmann::json& target);

/// One target of a targets file (read_disc_targets) as a row, `ours` not yet known.
DiscValidationRow disc_target_row(const nlohmann::json& target);

/// A row's window and provenance as JSON: quantity, units, low, high, reported, source.
nlohmann::json disc_target_json(const DiscValidationRow& row);

/// Reads the targets file; throws std::invalid_argument (one line) when it is unusable.
nlohmann::json read_disc_targets(const std::string& path);

/// Solves the five standard loads on `m` and compares with `targets` (read_disc_targets).
DiscValidationResult run_disc_validation(const mesh::TetMesh& m,
                                         const mesh::RegionMaterials& materials,
                                         fem::Formulation formulation,
                                         const nlohmann::json& targets,
                                         const std::string& mesh_label,
                                         const StageHooks& hooks = StageHooks());

/// The standard load cases of the nonlinear disc in order, each with the component of the disc
/// frame's (t, θ) it is measured along: compression 1, torsion 4, flexion and extension 3,
/// lateral bending 5.
const std::vector<std::pair<const char*, int>>& nonlinear_disc_cases();

/// The nonlinear disc's in-vitro quantities under the standard loads, keyed as the targets
/// file's ("compression", …, "nucleus-pressure-ratio"): absent where a case did not converge
/// (`notes` says why). Throws std::invalid_argument for options out of range.
struct NonlinearDiscQuantities {
  std::map<std::string, double> values;
  std::map<std::string, std::string> notes;
  std::vector<DiscLoadPath> paths;
  double nucleus_pressure_mpa = std::numeric_limits<double>::quiet_NaN();
  double fibre_k2 = 0;  ///< the toe exponent used
  Eigen::Index dofs = 0;
  int newton_iterations = 0;  ///< over the five cases
};
NonlinearDiscQuantities nonlinear_disc_quantities(const mesh::TetMesh& m,
                                                  const mesh::RegionMaterials& materials,
                                                  const NonlinearDiscOptions& options,
                                                  const StageHooks& hooks = StageHooks());

/// The same with the nonlinear disc. Throws std::invalid_argument for options out of range.
DiscValidationResult run_nonlinear_disc_validation(const mesh::TetMesh& m,
                                                   const mesh::RegionMaterials& materials,
                                                   const NonlinearDiscOptions& options,
                                                   const nlohmann::json& targets,
                                                   const std::string& mesh_label,
                                                   const StageHooks& hooks = StageHooks());

/// The paths as CSV: load_case, load, load_units, motion, motion_units.
void write_disc_paths_csv(std::ostream& os, const DiscValidationResult& r);

void print_disc_validation(std::ostream& os, const DiscValidationResult& r, bool markdown = false);
nlohmann::json disc_validation_json(const DiscValidationResult& r);
void write_disc_validation_csv(std::ostream& os, const DiscValidationResult& r);

}  // namespace spinesim::studies
