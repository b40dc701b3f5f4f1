#include "spinesim/calibration/levels.hpp"

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace spinesim::calibration {

std::pair<std::string, mesh::TetMesh> coarser_level_mesh(const std::string& level,
                                                         mesh::MeshOptions options,
                                                         const std::string& data_dir,
                                                         const StatusLine& status) {
  const mesh::DiscDimensions dims = mesh::disc_dimensions(level, data_dir);
  options.cell_size_mm *= 1.5;
  std::ostringstream label;
  label << "parametric " << dims.level << ", cell size " << std::setprecision(3)
        << options.cell_size_mm << " mm";
  if (status) status("meshing the second resolution: " + label.str());
  return {label.str(), mesh::mesh_disc_level(dims.level, options, data_dir)};
}

double CellSizeRule::cell_size_mm(double height_mm) const {
  return std::min(max_mm, height_mm / cells_through_height);
}

std::string CellSizeRule::describe() const {
  std::ostringstream s;
  s << "min(" << max_mm << " mm, disc height / " << cells_through_height << ")";
  return s.str();
}

void validate(const CellSizeRule& rule) {
  if (!(rule.max_mm >= 0.5 && rule.max_mm <= 10))
    throw std::invalid_argument("--max-cell-size must be 0.5 to 10 mm");
  if (!(rule.cells_through_height >= 1 && rule.cells_through_height <= 20))
    throw std::invalid_argument("--cells-through-height must be 1 to 20");
}

double default_level_cell_size_mm(const std::string& level, const std::string& data_dir,
                                  const CellSizeRule& rule) {
  return rule.cell_size_mm(mesh::disc_dimensions(level, data_dir).height_mm);
}

LevelMeshes mesh_level(const std::string& level,
                       const std::optional<mesh::StructuredDiscOptions>& structured,
                       double cell_size_mm, bool transfer, const std::string& data_dir,
                       const StatusLine& status) {
  LevelMeshes out;
  if (structured) {
    if (status) status("meshing " + level + " (structured)");
    out.mesh = mesh::mesh_structured_level(level, *structured, data_dir);
    mesh::StructuredDiscOptions finer = *structured;
    finer.sectors += 4;
    if (transfer)
      out.transfer.emplace_back("structured, " + std::to_string(finer.sectors) + " sectors",
                                mesh::mesh_structured_level(level, finer, data_dir));
    return out;
  }
  mesh::MeshOptions options;
  options.cell_size_mm = cell_size_mm;
  if (status)
    status("meshing " + level + " (cell size " + std::to_string(cell_size_mm).substr(0, 4) +
           " mm)");
  out.mesh = mesh::mesh_disc_level(level, options, data_dir);
  if (transfer) out.transfer.push_back(coarser_level_mesh(level, options, data_dir, status));
  return out;
}

std::string AllLevelsResult::failed() const {
  std::string list;
  for (const auto& l : levels)
    if (!l.success) list += (list.empty() ? "" : ", ") + l.level + " (" + l.status + ")";
  return list;
}

namespace {

double worst(const nlohmann::json& rows, const char* key) {
  double w = 0;
  for (const auto& r : rows) w = std::max(w, r[key].get<double>());
  return w;
}

/// The worst errors of the training and held-out rows of a tuned file's report.
void summarise_errors(const nlohmann::json& rep, LevelCalibration& row) {
  row.train_untuned = worst(rep["train"], "untuned_error");
  row.train_tuned = worst(rep["train"], "tuned_error");
  if (!rep["holdout"].empty()) {
    row.holdout_untuned = worst(rep["holdout"], "untuned_error");
    row.holdout_tuned = worst(rep["holdout"], "tuned_error");
  }
}

/// The report's numbers of one level, from its tuned file's report.
void summarise(const CalibrationOutcome& o, LevelCalibration& row) {
  row.success = o.result.success;
  row.status = o.result.status;
  row.iterations = o.result.iterations;
  row.seconds = o.total_seconds;
  if (!row.success) return;
  const auto& rep = o.tuned.report;
  summarise_errors(rep, row);
  row.k6_ratio_min = 1e300, row.k6_ratio_max = 0;
  for (const auto& v : rep["stiffness_diagonal"]["ratio_tuned"]) {
    row.k6_ratio_min = std::min(row.k6_ratio_min, v.get<double>());
    row.k6_ratio_max = std::max(row.k6_ratio_max, v.get<double>());
  }
}

void summarise(const NonlinearCalibrationOutcome& o, LevelCalibration& row) {
  row.success = o.success;
  row.status = o.fit.fit.status;
  row.iterations = o.fit.fit.iterations;
  row.seconds = o.total_seconds;
  row.k6_ratio_min = row.k6_ratio_max = NAN;
  if (!row.success) return;
  const auto& rep = o.tuned.report;
  summarise_errors(rep, row);
  row.train_reaction_tuned = worst(rep["train"], "tuned_reaction_error");
  if (!rep["holdout"].empty())
    row.holdout_reaction_tuned = worst(rep["holdout"], "tuned_reaction_error");
}

}  // namespace

AllLevelsResult calibrate_all_levels(const mesh::RegionMaterials& materials,
                                     const AllLevelsRequest& request,
                                     const LevelProgress& progress) {
  const CalibrationRequest& rq = request.calibration;
  if (!rq.transfer_meshes.empty())
    throw std::invalid_argument(
        "--transfer-mesh is one disc's: with --level all each level is checked at 1.5x its cell "
        "size");
  if (rq.per_spring)
    throw std::invalid_argument(
        "--per-spring fits one mesh: --level all writes region-level scales, which transfer to "
        "other meshes");
  const std::vector<std::string>& levels =
      request.levels.empty() ? mesh::disc_levels() : request.levels;
  const std::string& data_dir = request.data_dir;
  for (const auto& level : levels) mesh::disc_dimensions(level, data_dir);  // known levels

  AllLevelsResult r;
  r.set.material_name = materials.name;
  r.set.generated_by = request.generated_by;
  r.set.settings = {{"check_load_scale", rq.nonlinear_check ? nlohmann::json(rq.check_load_scale)
                                                            : nlohmann::json(nullptr)}};
  if (request.nonlinear) {
    validate(*request.nonlinear);
    r.set.settings = {{"reference", "nonlinear FEM"},
                      {"load_levels", request.nonlinear->load_levels},
                      {"fem_order", request.nonlinear->fem_order},
                      {"check_load_scale", nullptr}};
  }
  if (request.structured) {
    mesh::validate(*request.structured);
    r.set.settings["mesh"] =
        "structured disc (data/disc_morphometry.csv), placed in the spine (as `mesh disc --level "
        "--structured`)";
    r.set.settings["structured"] = {{"sectors", request.structured->sectors},
                                    {"rings", request.structured->rings},
                                    {"layers", request.structured->layers},
                                    {"match_area", request.structured->match_area}};
  } else {
    r.set.settings["mesh"] =
        "parametric disc (data/disc_morphometry.csv), CGAL, placed in the spine (as `mesh disc "
        "--level`)";
    validate(request.cell_size_rule);
    r.set.settings["cell_size_rule"] =
        request.cell_size_mm ? "as given" : request.cell_size_rule.describe();
  }
  nlohmann::json cell_by_level = nlohmann::json::object();
  int done = 0;
  for (const std::string& level : levels) {
    const StatusLine status = [&](const std::string& s) {
      if (progress) progress(done, level + ": " + s);
    };
    LevelCalibration row;
    if (!request.structured) {
      row.cell_size_mm = request.cell_size_mm
                             ? *request.cell_size_mm
                             : default_level_cell_size_mm(level, data_dir, request.cell_size_rule);
      cell_by_level[level] = row.cell_size_mm;
    }
    LevelMeshes meshes = mesh_level(level, request.structured, row.cell_size_mm,
                                    request.transfer && !request.nonlinear, data_dir, status);
    const mesh::TetMesh& m = meshes.mesh;
    row.level = level;
    row.tets = m.num_tets();
    if (request.nonlinear) {
      const NonlinearCalibrationOutcome o =
          calibrate_disc_nonlinear(m, materials, *request.nonlinear, status);
      summarise(o, row);
      if (row.success) r.set.levels.emplace(level, o.tuned);
    } else {
      CalibrationRequest level_rq = rq;
      level_rq.transfer_meshes = std::move(meshes.transfer);
      const CalibrationOutcome o = calibrate_disc(m, materials, level_rq, status);
      summarise(o, row);
      if (row.success) r.set.levels.emplace(level, o.tuned);
    }
    ++done;
    r.levels.push_back(row);
  }
  if (!request.structured) r.set.settings["cell_size_mm"] = cell_by_level;
  return r;
}

}  // namespace spinesim::calibration
