#include "spinesim/studies/spine_database.hpp"

#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <stdexcept>

namespace spinesim::studies {
namespace sp = spinesim::spine;
using nlohmann::json;

const char* const kDatabaseSource =
    "spinesim's spine model (data/thesis tables F.1-F.19, appendix C, data/spine/spine_model.json) "
    "solved by "
    "spine::solve_spine (quasi-static equilibrium under gravity, Ipopt muscle recruitment) with "
    "the force on the "
    "loaded vertebra's F.1 centre along +-x, +-y, +-z, 0-600 N in 50 N steps (thesis 3.5); "
    "least-squares polynomial "
    "fits, degree chosen by residual";

std::vector<sp::SuperpositionCase> oblique_cases(const std::vector<int>& vertebrae,
                                                 const std::vector<double>& magnitudes_n,
                                                 const sp::DisplacementDatabase& db) {
  std::vector<int> on;
  for (int v : vertebrae)
    if (db.has_vertebra(v)) on.push_back(v);
  for (int v = 0; on.empty() && v < sp::kDbVertebrae; ++v)  // none of them in the file: its first
    if (db.has_vertebra(v)) on.push_back(v);
  return sp::superposition_cases(on, magnitudes_n);
}

DatabaseBuild generate_database(const std::string& data_dir, const DatabaseRequest& rq,
                                const StageHooks& hooks, const SolveProgress& solves) {
  // 1. The model the file describes.
  hooks.begin_stage("loading the spine model");
  const sp::SpineModel model = sp::load_spine_model(data_dir, rq.model);
  hooks.end_stage();

  // 2. Every (vertebra, direction, force) solve, baseline first.
  sp::GenerationOptions g;
  g.solve = rq.solve;
  g.loaded_vertebrae = rq.loaded_vertebrae;
  g.workers = rq.workers;
  g.progress = solves;
  DatabaseBuild b;
  b.loaded_vertebrae =
      g.loaded_vertebrae.empty() ? sp::kDbVertebrae : int(g.loaded_vertebrae.size());
  hooks.begin_stage("solving " + std::to_string(b.loaded_vertebrae * sp::kDbDirections * 12 + 1) +
                    " load cases");
  b.samples = sp::sample_responses(model, g);
  hooks.end_stage(std::to_string(b.samples.failed.size()) + " failed");

  // 3. Fits, then the oblique forces against them.
  b.db = sp::DisplacementDatabase::fit(b.samples, g.tolerance);
  b.db.info.generated_by = rq.generated_by;
  b.db.info.source = kDatabaseSource;
  b.db.info.model = rq.model;
  const auto cases = oblique_cases(rq.superposition_on, rq.magnitudes_n, b.db);
  hooks.begin_stage("superposition check: " + std::to_string(cases.size()) + " oblique forces");
  b.db.info.superposition =
      sp::check_superposition(model, b.db, cases, g.solve, rq.workers, solves);
  b.db.info.has_superposition = true;
  hooks.end_stage();
  return b;
}

void print_database_build(std::ostream& os, const DatabaseBuild& b) {
  os << "Displacement-force database: " << b.loaded_vertebrae
     << " loaded vertebrae x 6 directions x 12 forces + baseline = " << b.samples.solves
     << " solves, " << b.samples.workers << " workers, " << fixed(b.samples.seconds, 1) << " s\n";
  print_residuals(b.db.info, os);
  print_failed(b.samples.failed, os);
  print_out_of_plane(b.samples.out_of_plane, os);
  print_superposition(b.db.info.superposition, os);
}

namespace {

json grid_json(const std::vector<GridRow>& rows) {
  json grid = json::array();
  for (const auto& r : rows)
    grid.push_back({{"vertebra", sp::vertebra_names()[std::size_t(r.vertebra)]},
                    {"direction", sp::direction_names()[std::size_t(r.direction)]},
                    {"force_n", r.force_n},
                    {"error_mm", r.error_mm},
                    {"error_deg", r.error_deg},
                    {"allowed_mm", r.allowed_mm},
                    {"allowed_deg", r.allowed_deg},
                    {"ok", r.ok()},
                    {"message", r.message}});
  return grid;
}

void print_grid(const std::vector<GridRow>& rows, std::ostream& os) {
  TextTable t({"vertebra", "direction", "force (N)", "error (mm)", "allowed (mm)", "error (deg)",
               "allowed (deg)", "verdict"},
              2);
  for (const auto& r : rows)
    t.add({sp::vertebra_names()[std::size_t(r.vertebra)],
           sp::direction_names()[std::size_t(r.direction)], fixed(r.force_n, 0),
           fixed(r.error_mm, 4), fixed(r.allowed_mm, 4), fixed(r.error_deg, 4),
           fixed(r.allowed_deg, 4),
           r.ok()              ? "ok"
           : r.message.empty() ? "MISMATCH"
                               : "FAILED " + r.message});
  t.print(os, false);
}

/// The grid of a check: per vertebra of the oblique cases, every direction at half and full force.
std::vector<GridRow> grid_rows(const std::vector<sp::SuperpositionCase>& cases, double force_max_n,
                               std::vector<std::vector<sp::ExternalLoad>>& loads) {
  std::vector<GridRow> rows;
  loads = {{}};  // the gravity-only solve first
  for (const auto& c : cases) {
    if (!rows.empty() && rows.back().vertebra == c.vertebra) continue;
    for (int d = 0; d < sp::kDbDirections; ++d)
      for (double f : {0.5 * force_max_n, force_max_n}) {
        GridRow r;
        r.vertebra = c.vertebra, r.direction = d, r.force_n = f;
        rows.push_back(r);
        sp::ExternalLoad l;
        l.vertebra = c.vertebra;
        l.force_n = f * sp::direction_vector(d);
        loads.push_back({l});
      }
  }
  return rows;
}

}  // namespace

spine::DisplacementDatabase read_database(const std::string& path) {
  try {
    return spine::DisplacementDatabase::load(path);
  } catch (const std::runtime_error& e) {  // load's contract for a bad file: runtime_error
    throw std::invalid_argument(e.what());
  }
}

DatabaseCheck check_database(const std::string& data_dir, const std::string& path,
                             const std::vector<int>& superposition_on,
                             const std::vector<double>& magnitudes_n, int workers,
                             const StageHooks& hooks, const SolveProgress& solves) {
  DatabaseCheck c;
  c.path = path;
  hooks.begin_stage("loading " + path + " and its model");
  const sp::DisplacementDatabase db = read_database(path);
  const sp::SpineModel model = sp::load_spine_model(data_dir, db.info.model);
  const sp::SolveOptions& so = db.info.solve;
  c.generated_by = db.info.generated_by;
  hooks.end_stage();

  const auto cases = oblique_cases(superposition_on, magnitudes_n, db);
  std::vector<std::vector<sp::ExternalLoad>> loads;
  c.grid = grid_rows(cases, db.force_max_n(), loads);
  hooks.begin_stage("re-solving " + std::to_string(c.grid.size()) + " grid forces");
  std::vector<sp::VertebraResponse> disp;
  std::vector<std::string> errors;
  sp::solve_cases(model, loads, so, workers, disp, errors, solves);
  if (!errors[0].empty()) throw std::runtime_error("the gravity-only solve failed: " + errors[0]);
  std::tie(c.baseline_mm, c.baseline_deg) = sp::max_response_difference(disp[0], db.baseline());
  bool all_ok = c.baseline_mm <= c.margin && c.baseline_deg <= c.margin;
  for (std::size_t i = 0; i < c.grid.size(); ++i) {
    GridRow& r = c.grid[i];
    r.allowed_mm = db.max_residual_translation_mm(r.vertebra, r.direction) + c.margin;
    r.allowed_deg = db.max_residual_rotation_deg(r.vertebra, r.direction) + c.margin;
    if (!errors[i + 1].empty()) {
      r.message = errors[i + 1];
      // A force the file also failed at is consistent, not a mismatch.
      bool known = false;
      for (const auto& f : db.info.failed)
        known = known ||
                (f.vertebra == r.vertebra && f.direction == r.direction && f.force_n == r.force_n);
      if (known) r.message = "";
      all_ok = all_ok && known;
      continue;
    }
    sp::VertebraResponse from_db;
    db.evaluate(r.vertebra, r.force_n * sp::direction_vector(r.direction), from_db);
    std::tie(r.error_mm, r.error_deg) = sp::max_response_difference(from_db, disp[i + 1] - disp[0]);
    all_ok = all_ok && r.ok();
  }
  hooks.end_stage();
  hooks.begin_stage("superposition check: " + std::to_string(cases.size()) + " oblique forces");
  c.superposition = sp::check_superposition(model, db, cases, so, workers, solves);
  hooks.end_stage();
  c.ok = all_ok;
  return c;
}

json database_check_json(const DatabaseCheck& c) {
  return {{"file", c.path},
          {"generated_by", c.generated_by},
          {"baseline_difference_mm", c.baseline_mm},
          {"baseline_difference_deg", c.baseline_deg},
          {"grid", grid_json(c.grid)},
          {"superposition_check", json::parse(sp::superposition_json_text(c.superposition))},
          {"ok", c.ok}};
}

void print_database_check(std::ostream& os, const DatabaseCheck& c) {
  os << "Checking " << c.path << " (" << c.generated_by << ")\n"
     << "Baseline (gravity only) vs file: " << fixed(c.baseline_mm, 5) << " mm, "
     << fixed(c.baseline_deg, 5) << " deg\n"
     << "Grid forces re-solved (error = max over vertebrae; allowed = the file's max fit residual "
        "+ "
     << c.margin << "):\n";
  print_grid(c.grid, os);
  print_superposition(c.superposition, os);
}

// --- report pieces ---------------------------------------------------------------------------

void print_residuals(const sp::DatabaseInfo& info, std::ostream& os) {
  const auto& r = info.residuals;
  os << "Fits: " << r.fits << " (per degree 1-5:";
  for (int d = 1; d <= sp::kDbMaxDegree; ++d) os << " " << r.degree_count[std::size_t(d)];
  os << "), " << r.fits_above_tolerance << " above tolerance (RMS > max("
     << 100 * info.tolerance.relative << " % of range, " << info.tolerance.absolute << "))\n";
  TextTable t({"direction", "max mm", "rms mm", "max deg", "rms deg", "above tol"});
  auto row = [&](const std::string& name, const sp::ResidualSummary& s) {
    t.add({name, fixed(s.max_translation_mm, 4), fixed(s.rms_translation_mm, 4),
           fixed(s.max_rotation_deg, 4), fixed(s.rms_rotation_deg, 4),
           std::to_string(s.fits_above_tolerance)});
  };
  for (int d = 0; d < sp::kDbDirections; ++d)
    row(sp::direction_names()[std::size_t(d)], info.residuals_per_direction[std::size_t(d)]);
  row("all", r);
  t.print(os, false, " ");
}

void print_failed(const std::vector<sp::FailedSolve>& failed, std::ostream& os) {
  os << "Failed solves (left out of the fits): "
     << (failed.empty() ? "none" : std::to_string(failed.size())) << "\n";
  for (const auto& f : failed)
    os << "  " << sp::vertebra_names()[std::size_t(f.vertebra)] << " "
       << sp::direction_names()[std::size_t(f.direction)] << " " << f.force_n << " N: " << f.message
       << "\n";
}

void print_out_of_plane(const std::vector<sp::OutOfPlaneSolve>& solves, std::ostream& os) {
  os << "Sagittal forces (+-y, +-z) whose solution left the sagittal plane (the model is "
        "symmetric, so a symmetric "
        "equilibrium exists): "
     << (solves.empty() ? "none" : std::to_string(solves.size())) << "\n";
  double mm = 0, deg = 0;
  std::string list;
  for (const auto& o : solves) {
    mm = std::max(mm, o.lateral_mm), deg = std::max(deg, o.lateral_deg);
    list += (list.empty() ? "" : ", ") + sp::vertebra_names()[std::size_t(o.vertebra)] +
            sp::direction_names()[std::size_t(o.direction)] + "@" + fixed(o.force_n, 0);
  }
  if (!solves.empty())
    os << "  worst |tx| " << fixed(mm, 3) << " mm, |(ry, rz)| " << fixed(deg, 3) << " deg: " << list
       << "\n";
}

namespace {
std::string percent(double error, double scale) {
  return scale > 0 ? fixed(100 * error / scale, 1) + "%" : "-";
}

}  // namespace

void print_superposition(const sp::SuperpositionReport& r, std::ostream& os) {
  os << "Superposition of axis responses vs a direct solve (max over the 17 vertebrae; % of the "
        "max response):\n";
  TextTable t({"on", "plane", "|F| N", "resp mm", "resp deg", "db err mm", "db err deg",
               "axis-sum mm", "axis-sum deg", "note"},
              2);
  for (const auto& c : r.cases) {
    const std::string vertebra = sp::vertebra_names()[std::size_t(c.vertebra)];
    if (!c.solved) {
      t.add(
          {vertebra, c.plane, fixed(c.force_n.norm(), 0), "-", "-", "-", "-", "-", "-", c.message});
      continue;
    }
    auto pair = [&](double e, double scale) {
      return fixed(e, 3) + " (" + percent(e, scale) + ")";
    };
    std::string note = c.extrapolated ? "extrapolated" : "";
    if (!c.message.empty()) note += (note.empty() ? "" : "; ") + c.message;
    t.add({vertebra, c.plane, fixed(c.force_n.norm(), 0), fixed(c.response_translation_mm, 2),
           fixed(c.response_rotation_deg, 2),
           pair(c.db_error_translation_mm, c.response_translation_mm),
           pair(c.db_error_rotation_deg, c.response_rotation_deg),
           pair(c.axis_sum_error_translation_mm, c.response_translation_mm),
           pair(c.axis_sum_error_rotation_deg, c.response_rotation_deg), note});
  }
  t.print(os, false, " ");
  os << "Worst (database: within the solved range): database " << fixed(r.max_db_translation_mm, 3)
     << " mm (" << fixed(100 * r.max_db_translation_relative, 1) << " %), "
     << fixed(r.max_db_rotation_deg, 3) << " deg (" << fixed(100 * r.max_db_rotation_relative, 1)
     << " %); sum of direct axis solves " << fixed(r.max_axis_sum_translation_mm, 3) << " mm ("
     << fixed(100 * r.max_axis_sum_translation_relative, 1) << " %), "
     << fixed(r.max_axis_sum_rotation_deg, 3) << " deg ("
     << fixed(100 * r.max_axis_sum_rotation_relative, 1) << " %)\n";
}

}  // namespace spinesim::studies
