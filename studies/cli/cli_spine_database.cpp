// spinesim spine database — thesis 3.5's displacement–force database for the haptic loop
// (spine/database.hpp): the spine solved under 0…600 N in 50 N steps on each vertebra T1…L5
// along ±x, ±y, ±z, every vertebra's 6-DOF response fitted by least-squares polynomials, the
// compact file written, and the thesis's superposition assumption (an oblique force's response
// is the sum of its axis responses) measured against direct solves.
//
//   spinesim spine database --out data/spine/displacement_db.json      # the shipped file
//   spinesim spine database --vertebrae T1,L3 --out part.json --json   # a subset
//   spinesim spine database --check                                   # verify the shipped file
//
// --check regenerates nothing: it loads the file (--out, default the shipped one), re-solves a
// sample of grid forces and the oblique cases with the model the file names, and exits 1 when a
// grid response differs from the file by more than its stored fit residual (+ margin).
#include "cli_common.hpp"

#include "spinesim/common/timer.hpp"

#include "spinesim/spine/database.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace spinesim::cli {
namespace {
using nlohmann::json;
namespace sp = spinesim::spine;

constexpr const char* kSource =
    "spinesim's spine model (data/thesis tables F.1-F.19, appendix C, data/spine/spine_model.json) "
    "solved by "
    "spine::solve_spine (quasi-static equilibrium under gravity, Ipopt muscle recruitment) with "
    "the force on the "
    "loaded vertebra's F.1 centre along +-x, +-y, +-z, 0-600 N in 50 N steps (thesis 3.5); "
    "least-squares polynomial "
    "fits, degree chosen by residual";

struct DatabaseArgs {
  std::string out = "displacement_db.json", vertebrae, fusion, superposition_on = "T1,T7,L3";
  std::string magnitudes = "200,400,600";
  CLI::Option* out_option = nullptr;
  int workers = 0;
  bool check = false, no_recruit = false, json = false, quiet = false;
};

std::vector<int> vertebra_list(const std::string& text) {
  std::vector<int> out;
  for (const auto& name : split_list(text)) out.push_back(sp::vertebra_index(name));
  return out;
}

sp::SolveOptions solve_options(bool recruit) {
  sp::SolveOptions o;
  o.recruit = recruit;
  return o;
}

// --- report ----------------------------------------------------------------------------------

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

std::string percent(double error, double scale) {
  return scale > 0 ? fixed(100 * error / scale, 1) + "%" : "-";
}

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

std::vector<double> magnitudes(const DatabaseArgs& a) {
  const Eigen::VectorXd m =
      parse_numbers(a.magnitudes, int(split_list(a.magnitudes).size()), "--magnitudes");
  if (m.size() == 0 || m.minCoeff() <= 0)
    throw std::invalid_argument("--magnitudes: give forces > 0 N");
  return std::vector<double>(m.data(), m.data() + m.size());
}

std::vector<sp::SuperpositionCase> oblique_cases(const DatabaseArgs& a,
                                                 const sp::DisplacementDatabase& db) {
  std::vector<int> on;
  for (int v : vertebra_list(a.superposition_on))
    if (db.has_vertebra(v)) on.push_back(v);
  for (int v = 0; on.empty() && v < sp::kDbVertebrae;
       ++v)  // a subset without T1/T7/L3: its first vertebra
    if (db.has_vertebra(v)) on.push_back(v);
  return sp::superposition_cases(on, magnitudes(a));
}

/// Everything a long run could trip over at its end, refused before it starts.
void validate(const DatabaseArgs& a) {
  if (a.workers < 0) throw std::invalid_argument("--workers must be >= 0");
  vertebra_list(a.vertebrae);
  if (vertebra_list(a.superposition_on).empty())
    throw std::invalid_argument("--superposition-on: no vertebra given");
  magnitudes(a);
  if (!a.fusion.empty()) sp::parse_fusion(a.fusion);
  if (!a.check) {
    const auto dir = std::filesystem::absolute(a.out).parent_path();
    if (!std::filesystem::is_directory(dir))
      throw std::invalid_argument("--out: no folder " + dir.string());
  }
}

// --- generate --------------------------------------------------------------------------------

std::string command_line(const DatabaseArgs& a) {
  std::string c = "spinesim spine database --out " + a.out;
  if (!a.vertebrae.empty()) c += " --vertebrae " + a.vertebrae;
  if (!a.fusion.empty()) c += " --fusion " + a.fusion;
  if (a.no_recruit) c += " --no-recruit";
  if (a.superposition_on != DatabaseArgs().superposition_on)
    c += " --superposition-on " + a.superposition_on;
  if (a.magnitudes != DatabaseArgs().magnitudes) c += " --magnitudes " + a.magnitudes;
  return c;
}

void run_generate(const DatabaseArgs& a) {
  const Timer t0;
  Progress progress(4, a.quiet);
  // 1. The model the file describes.
  progress.begin("loading the spine model");
  sp::ModelOptions mo;
  if (!a.fusion.empty()) mo.fused_joints = sp::parse_fusion(a.fusion);
  const sp::SpineModel model = sp::load_spine_model(data_dir(), mo);
  progress.end();

  // 2. Every (vertebra, direction, force) solve, baseline first.
  sp::GenerationOptions g;
  g.solve = solve_options(!a.no_recruit);
  g.loaded_vertebrae = vertebra_list(a.vertebrae);
  g.workers = a.workers;
  ProgressBar solves(0, progress.quiet(), "solves");
  g.progress = solves.callback();
  const int nv = g.loaded_vertebrae.empty() ? sp::kDbVertebrae : int(g.loaded_vertebrae.size());
  progress.begin("solving " + std::to_string(nv * sp::kDbDirections * 12 + 1) + " load cases");
  const sp::ResponseSamples samples = sp::sample_responses(model, g);
  progress.end(std::to_string(samples.failed.size()) + " failed");

  // 3. Fits, then the oblique forces against them.
  sp::DisplacementDatabase db = sp::DisplacementDatabase::fit(samples, g.tolerance);
  db.info.generated_by = command_line(a);
  db.info.source = kSource;
  db.info.model = mo;
  const auto cases = oblique_cases(a, db);
  progress.begin("superposition check: " + std::to_string(cases.size()) + " oblique forces");
  solves.finish();
  db.info.superposition =
      sp::check_superposition(model, db, cases, g.solve, a.workers, solves.callback());
  solves.finish();
  db.info.has_superposition = true;
  progress.end();

  // 4. The file, then the report (re-read from the file, so what is printed is what was written).
  progress.begin("writing " + a.out);
  db.save(a.out);
  progress.end();
  std::ifstream in(a.out);
  json file = json::parse(in);
  if (a.json) {
    file.erase("fits");
    file.erase("baseline");
    file["file"] = a.out;
    file["bytes"] = std::filesystem::file_size(a.out);
    file["total_seconds"] = t0.seconds();
    print_json(file);
    return;
  }
  std::cout << "Displacement-force database: " << nv
            << " loaded vertebrae x 6 directions x 12 forces + baseline = " << samples.solves
            << " solves, " << samples.workers << " workers, " << fixed(samples.seconds, 1)
            << " s\n";
  print_residuals(db.info, std::cout);
  print_failed(samples.failed, std::cout);
  print_out_of_plane(samples.out_of_plane, std::cout);
  print_superposition(db.info.superposition, std::cout);
  std::cout << "Wrote " << a.out << " (" << std::filesystem::file_size(a.out) / 1024
            << " KiB), total " << fixed(t0.seconds(), 1) << " s\n";
}

// --- check -----------------------------------------------------------------------------------

/// Grid forces re-solved: vertebrae of the superposition check, every direction, 300 and 600 N.
struct GridRow {
  int vertebra = 0, direction = 0;
  double force_n = 0, error_mm = 0, error_deg = 0, allowed_mm = 0, allowed_deg = 0;
  std::string message;
  bool ok() const { return message.empty() && error_mm <= allowed_mm && error_deg <= allowed_deg; }
};

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

void run_check(const DatabaseArgs& a) {
  const std::string path =
      a.out_option->count() ? a.out : data_dir() + "/spine/displacement_db.json";
  Progress progress(3, a.quiet);
  progress.begin("loading " + path + " and its model");
  const sp::DisplacementDatabase db = sp::DisplacementDatabase::load(path);
  const sp::SpineModel model = sp::load_spine_model(data_dir(), db.info.model);
  const sp::SolveOptions& so = db.info.solve;
  progress.end();

  const auto cases = oblique_cases(a, db);
  std::vector<GridRow> rows;
  std::vector<std::vector<sp::ExternalLoad>> loads = {{}};
  for (const auto& c : cases) {
    if (!rows.empty() && rows.back().vertebra == c.vertebra) continue;
    for (int d = 0; d < sp::kDbDirections; ++d)
      for (double f : {0.5 * db.force_max_n(), db.force_max_n()}) {
        GridRow r;
        r.vertebra = c.vertebra, r.direction = d, r.force_n = f;
        rows.push_back(r);
        sp::ExternalLoad l;
        l.vertebra = c.vertebra;
        l.force_n = f * sp::direction_vector(d);
        loads.push_back({l});
      }
  }
  progress.begin("re-solving " + std::to_string(rows.size()) + " grid forces");
  std::vector<sp::VertebraResponse> disp;
  std::vector<std::string> errors;
  ProgressBar solves(0, progress.quiet(), "solves");
  sp::solve_cases(model, loads, so, a.workers, disp, errors, solves.callback());
  solves.finish();
  if (!errors[0].empty()) throw std::runtime_error("the gravity-only solve failed: " + errors[0]);
  // The solver stops at a gradient tolerance, and the coefficients are rounded: a small margin.
  const double margin = 1e-3;
  const auto [base_mm, base_deg] = sp::max_response_difference(disp[0], db.baseline());
  bool all_ok = base_mm <= margin && base_deg <= margin;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    GridRow& r = rows[i];
    r.allowed_mm = db.max_residual_translation_mm(r.vertebra, r.direction) + margin;
    r.allowed_deg = db.max_residual_rotation_deg(r.vertebra, r.direction) + margin;
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
  progress.end();
  progress.begin("superposition check: " + std::to_string(cases.size()) + " oblique forces");
  const sp::SuperpositionReport sup =
      sp::check_superposition(model, db, cases, so, a.workers, solves.callback());
  solves.finish();
  progress.end();

  if (a.json) {
    print_json({{"file", path},
                {"generated_by", db.info.generated_by},
                {"baseline_difference_mm", base_mm},
                {"baseline_difference_deg", base_deg},
                {"grid", grid_json(rows)},
                {"superposition_check", json::parse(sp::superposition_json_text(sup))},
                {"ok", all_ok}});
  } else {
    std::cout << "Checking " << path << " (" << db.info.generated_by << ")\n"
              << "Baseline (gravity only) vs file: " << fixed(base_mm, 5) << " mm, "
              << fixed(base_deg, 5) << " deg\n"
              << "Grid forces re-solved (error = max over vertebrae; allowed = the file's max fit "
                 "residual + "
              << margin << "):\n";
    print_grid(rows, std::cout);
    print_superposition(sup, std::cout);
  }
  if (!all_ok)
    throw std::runtime_error(
        path + " does not match the model: re-solved responses differ beyond the fit residuals");
}

}  // namespace

void register_spine_database(CLI::App& spine) {
  auto a = std::make_shared<DatabaseArgs>();
  auto* cmd = spine.add_subcommand("database",
                                   "Thesis 3.5 displacement-force database: solve, fit, write; "
                                   "measure the superposition assumption");
  a->out_option = cmd->add_option("--out", a->out,
                                  "Database file (JSON); with --check the file checked "
                                  "(default there: data/spine/displacement_db.json)")
                      ->capture_default_str();
  cmd->add_flag("--check", a->check,
                "Verify an existing file against direct solves instead of generating one");
  cmd->add_option("--vertebrae", a->vertebrae, "Loaded vertebrae, e.g. T1,L3 (default: T1…L5)");
  cmd->add_option("--fusion", a->fusion, "Fused levels of the model, e.g. L3-L4,L4-L5");
  cmd->add_flag("--no-recruit", a->no_recruit, "Muscles off (passive spine)");
  cmd->add_option("--superposition-on", a->superposition_on,
                  "Vertebrae loaded by the oblique forces")
      ->capture_default_str();
  cmd->add_option("--magnitudes", a->magnitudes, "Oblique force magnitudes, N")
      ->capture_default_str();
  cmd->add_option("--workers", a->workers, "Solver threads (0: one per core)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "One JSON object on stdout (the file's metadata, or the check)");
  cmd->add_flag("--quiet", a->quiet, "No progress on stderr");
  cmd->callback([a] {
    validate(*a);
    if (a->check)
      run_check(*a);
    else
      run_generate(*a);
  });
}

}  // namespace spinesim::cli
