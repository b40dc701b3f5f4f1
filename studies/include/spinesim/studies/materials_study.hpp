// The material comparison study (`spinesim study materials`, and a section of `spinesim demo`):
// one disc mesh, several materials, the same loads; for each material the linear FEM reference,
// the untuned thesis mass-spring disc and the mass-spring disc calibrated to that FEM, side by
// side — the thesis's fig. 5.9 (disc compression per material) with a reference beside it.
//
// Protocol, per material (same mesh for all; plate centre c = mean of the superior-endplate
// vertices; inferior endplate fixed, superior endplate a rigid plate):
//   1. FEM P2 on the mesh: the 6x6 plate stiffness K6, and the `compression` case
//      (fem/load_cases.hpp: F_y = -500 N in the disc frame, the thesis's fig. 5.9 load), linear.
//   2. calibrate_disc (calibration/protocol.hpp): Ipopt fits the per-region stiffness scales of the
//      chosen terms (default thesis+volume, as `spinesim calibrate`) to the FEM on the training
//      cases compression, shear-ap, flexion, torsion; no nonlinear check. It returns the linear
//      K6 of the untuned and the tuned MSS (rest Hessian condensed onto the plate's 6 DOF).
//   3. the untuned MSS — the thesis network (main + radial + torsion springs, Van Gelder
//      constants, every scale 1) — and the tuned MSS: nonlinear static equilibrium
//      (mss::solve_static) under the same wrench on the superior plate (PlateMode::wrench).
// Quantities per model, disc frame (x lateral, y axial, z anterior):
//   axial stiffness    K6_yy, N/mm (linear, at rest);
//   6x6 diagonal       tx ty tz N/mm, rx ry rz N·mm/deg (linear, at rest);
//   plate u_y          the superior plate's axial translation under the compression, mm
//                      (negative: towards the inferior endplate);
//   max |u|            largest vertex displacement under the compression, mm;
//   volume change      (V - V0)/V0 under the compression, dimensionless. MSS: sum of signed
//                      tet volumes (MssModel::volume_mm3). FEM: the P1 volume of the mesh with
//                      its vertices moved by the FEM displacement (P2: the vertex values; the
//                      mid-edge nodes are not used), so it includes the second-order terms a
//                      linear FEM's div u would not;
//   displacement error ||u_mss - u_fem||_F / ||u_fem||_F over the mesh vertices under the
//                      compression (as `spinesim mss compare`; compression is a training case).
#pragma once

#include "spinesim/studies/calibration_summary.hpp"
#include "spinesim/studies/toolkit.hpp"

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

/// One model's answer for one material (FEM, untuned or tuned MSS).
struct ModelResponse {
  bool available = true;  ///< false: tuned MSS of a failed calibration (no numbers)
  fem::Vector6d stiffness_diagonal = fem::Vector6d::Zero();  ///< disc frame, N/mm and N·mm/deg
  double axial_stiffness_n_per_mm() const { return stiffness_diagonal(1); }
  double plate_axial_displacement_mm = 0;  ///< disc-frame u_y of the plate, mm (< 0 compresses)
  double max_displacement_mm = 0;
  double volume_change = 0;        ///< (V - V0)/V0
  double displacement_error = 0;   ///< vs the FEM (0 for the FEM itself)
  bool converged = true;           ///< MSS static solve converged (FEM: always)
  Eigen::Index inverted_tets = 0;  ///< MSS: inside-out tets at equilibrium
  int newton_iterations = 0;
  std::string message;  ///< why the static solve did not converge
};

struct MaterialResult {
  std::string material;
  double e_annulus_mpa = 0, e_nucleus_mpa = 0, nu_annulus = 0, nu_nucleus = 0;
  ModelResponse fem, untuned, tuned;
  std::string calibration_status;  ///< Ipopt's return status
  bool calibrated = false;         ///< Ipopt succeeded
  int ipopt_iterations = 0;
  std::map<std::string, double> scales;  ///< tuned knob -> scale (x Van Gelder)
  double fem_seconds = 0, calibration_seconds = 0, mss_seconds = 0;
};

struct MaterialsStudyOptions {
  TermSet terms = TermSet::thesis_volume;  ///< what the calibration tunes
  int fem_order = 2;
};

/// Stages of one material (FEM, calibration, untuned MSS, tuned MSS), for StageHooks.
inline constexpr int kStagesPerMaterial = 4;

/// Runs the protocol above for one material on `mesh` (endplate labels required). Throws
/// std::invalid_argument for bad input; a failed calibration is returned (calibrated false, the
/// tuned response unavailable), a non-converged static solve is recorded, not thrown.
MaterialResult study_material(const mesh::TetMesh& mesh, const mesh::RegionMaterials& materials,
                              const MaterialsStudyOptions& options = MaterialsStudyOptions(),
                              const StageHooks& hooks = StageHooks());

/// The study over several materials on one mesh: one study_material() each.
struct MaterialsStudy {
  std::string level;  ///< for reports
  double cell_size_mm = 0;
  MaterialsStudyOptions options;
  std::vector<MaterialResult> results;
  double seconds = 0;  ///< wall-clock of the materials' runs
  /// The materials whose calibration failed, comma-separated; empty when none did.
  std::string failed() const;
};

/// Stages: kStagesPerMaterial per material.
MaterialsStudy run_materials_study(const mesh::TetMesh& mesh,
                                   const std::vector<mesh::RegionMaterials>& materials,
                                   const MaterialsStudyOptions& options,
                                   const StageHooks& hooks = StageHooks());

/// The set-up: mesh, load, models and each material's constants.
void print_materials_header(std::ostream& os, const mesh::TetMesh& mesh, double cell_size_mm,
                            const MaterialsStudyOptions& options,
                            const std::vector<mesh::RegionMaterials>& materials);

/// The summary: study, level, mesh, load, units, every material's responses, `csv` (or null).
nlohmann::json materials_study_json(const mesh::TetMesh& mesh, const MaterialsStudy& study,
                                    const std::string& csv);

/// "E 4.2/1 MPa, nu 0.45/0.49" (annulus/nucleus when they differ): for echoing the inputs.
std::string describe_material(const mesh::RegionMaterials& materials);

/// Readable tables, one block per quantity: materials as rows, FEM / untuned MSS / tuned MSS
/// as columns, the unit in each block's title. Markdown tables when `markdown`.
void print_materials(std::ostream& os, const std::vector<MaterialResult>& results, int fem_order,
                     bool markdown);

/// CSV, one row per material x model (fem, untuned, tuned); units in the column names.
std::string materials_csv(const std::vector<MaterialResult>& results);

/// JSON array, one object per material with "fem", "untuned", "tuned" responses.
nlohmann::json materials_json(const std::vector<MaterialResult>& results);

}  // namespace spinesim::studies
