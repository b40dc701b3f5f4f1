// `spinesim mss` and `spinesim mss compare` as drivers: a disc mesh read from a file, the
// mass-spring model chosen (untuned Van Gelder constants, or a tuned disc or set that fixes the
// terms and scales), then one plate load solved or stepped (mss_run.hpp) and written, or the
// MSS-vs-FEM protocol on named load cases (calibration/compare.hpp).
#pragma once

#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace spinesim::studies {

/// Which constants a run uses. Untuned: `options` (terms, factors, damping) and the material
/// (a preset or a JSON file). Tuned (`params`, a tuned disc or set): the file's terms and
/// scales, `options`' damping, and its own material unless `material_given`.
struct MssModelRequest {
  mss::MssOptions options;
  std::string variant = "radial";  ///< the untuned variant's name (tables)
  std::string params;
  std::string material = "real-disc";
  bool material_given = false;
};

struct MssModelChoice {
  mss::MssOptions options;
  mesh::RegionMaterials materials;
  std::string constants = "untuned Van Gelder";  ///< or "tuned (FILE)"
  std::string variant;
  std::string params;
};

/// Reads the material or the tuned file (the mesh is not known yet: a tuned file's fit to the
/// mesh is checked by build_mss_model).
MssModelChoice choose_mss_model(const MssModelRequest& request, const std::string& data_dir);

/// The MSS for `m`: with a tuned file only after it was checked against the mesh and material (a
/// per-spring file: the very mesh it was fitted on); its note goes to stderr unless `quiet`.
mss::MssModel build_mss_model(const mesh::TetMesh& m, const MssModelChoice& choice, bool quiet);

/// `spinesim mss`: one plate load on the MSS of a mesh file.
struct MssFileRunRequest {
  std::string mesh_path;
  MssModelRequest model;
  MssRunRequest run;  ///< a motion or wrench in run.load.value (or none: `load_case`)
  const fem::LoadCase* load_case = nullptr;  ///< a named case, in the mesh's disc frame
  std::optional<Eigen::Vector3d> center;     ///< plate centre, mm (default: the mesh's)
  std::string out;                           ///< .vtu (end state) or .pvd (a dynamic run)
  bool quiet = false;                        ///< no note on stderr
};

struct MssFileRunResult {
  MssModelChoice choice;
  std::shared_ptr<const mss::MssModel> model;
  MssRunResult run;
  nlohmann::json json;  ///< mss_run_json with the mesh, model, load, case and output
  std::string warning;  ///< one line for the user (tets inside out), or empty
};

/// Checks everything (the load, the stepping, the output) before any work; reads the mesh,
/// builds the model, runs (stages: reading, building, solving or stepping, writing) and writes
/// --out only for a run that succeeded. A run that failed is returned (run.failed), not thrown.
MssFileRunResult run_mss_file(const MssFileRunRequest& request, const std::string& data_dir,
                              const StageHooks& hooks = StageHooks());
int mss_file_run_stages(const MssFileRunRequest& request);

/// `spinesim mss compare`: the MSS-vs-FEM protocol on the mesh file.
struct MssCompareRequest {
  std::string mesh_path;
  MssModelRequest model;
  std::vector<fem::LoadCase> cases;
  double load_scale = 1.0;
  int order = 2;
  std::string csv;
  bool quiet = false;
};

struct MssCompareResult {
  MssModelChoice choice;
  MssFemComparison comparison;
  Eigen::Index nodes = 0, tets = 0;
  nlohmann::json json;
};

/// Stages: reading, building the model, FEM assembly and factorisation, comparing (4).
MssCompareResult run_mss_compare(const MssCompareRequest& request, const std::string& data_dir,
                                 const StageHooks& hooks = StageHooks());

/// The readable heading and table of a comparison.
void print_mss_compare(std::ostream& os, const MssCompareRequest& request,
                       const MssCompareResult& r);

}  // namespace spinesim::studies
