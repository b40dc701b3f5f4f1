// spinesim calibrate — Ipopt tunes the mass-spring disc's stiffness scales so it reproduces the
// linear FEM on the same mesh (calibration/README.md), and writes tuned.json.
//
//   spinesim calibrate --mesh disc.vtu --out tuned.json
//   spinesim calibrate --level L4-L5 --train compression,flexion --holdout torsion --out tuned.json --json
//   spinesim calibrate --level L4-L5 --per-spring [--smoothness 1e-3] --out tuned.json
//   spinesim calibrate --level all --structured --out data/tuned_structured_discs.json
//
// Protocol: the FEM (P2 by default) answers every training and held-out case; Ipopt fits the
// per-region scales of the chosen terms to the training cases only (calibration/objective.hpp);
// then both the untuned (Van Gelder thesis network) and the tuned MSS are compared with the FEM
// on every case by the nonlinear static solver at the cases' loads x --check-load-scale (0.1: the
// linear regime the FEM describes) — the `mss compare --load-scale`
// protocol. tuned.json is written only when Ipopt succeeded. --per-spring adds a second stage: one
// multiplier per main spring on top of the fitted region scales (calibration/per_spring.hpp),
// reported beside the region-only fit; the file (kind "per-spring") then belongs to this mesh, and
// transfer meshes are checked with the region-level scales.
#include "cli_common.hpp"
#include "spinesim/studies/calibration_summary.hpp"

#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/mesher.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace spinesim::cli {
namespace {

struct CalibrateArgs {
  std::string mesh_path, level, material = "real-disc", out, terms = "thesis+volume";
  std::string train = "compression,shear-ap,flexion,torsion";
  std::string holdout;  ///< default: every other case
  double cell_size_mm = 2.0;
  CLI::Option* cell_size_option = nullptr;
  calibration::CellSizeRule cell_size_rule;  ///< --level all without --cell-size
  double check_load_scale = CalibrationRequest().check_load_scale;
  int order = 2;
  calibration::Weights weights;
  calibration::IpoptSettings ipopt;
  std::vector<std::string> transfer_meshes;
  bool no_transfer = false;
  bool no_check = false, json = false, quiet = false;
  bool per_spring = false;
  bool structured = false;  ///< the level's structured (haptic-resolution) disc
  mesh::StructuredDiscOptions structured_options;  ///< its resolution (--sectors, ...)
  calibration::PerSpringWeights per_spring_weights;
  CLI::Option* smoothness_option = nullptr;
  int per_spring_max_iterations = calibration::per_spring_ipopt_defaults().max_iterations;
  /// Against the nonlinear FEM at several load levels (calibration/nonlinear_protocol.hpp).
  bool nonlinear = false;
  std::vector<double> load_levels{0.1, 1.0};
  std::string fibre_stretch = "isochoric";
  CLI::App* cmd = nullptr;  ///< to ask which options were given
  bool given(const char* option) const { return cmd->count(option) > 0; }
};

/// --level all: every level's parametric disc, one tuned set file (tuned_set.hpp), written only
/// when every level succeeded (calibration/levels.hpp).
void run_all_levels(const CalibrateArgs& a, const CalibrationRequest& rq,
                    const std::optional<calibration::NonlinearCalibrationRequest>& nonlinear,
                    const mesh::RegionMaterials& materials) {
  AllLevelsRequest all;
  all.data_dir = data_dir();
  all.calibration = rq;
  all.nonlinear = nonlinear;
  if (a.cell_size_option->count()) all.cell_size_mm = a.cell_size_mm;
  all.cell_size_rule = a.cell_size_rule;
  all.transfer = !a.no_transfer;
  if (a.structured) all.structured = a.structured_options;
  std::ostringstream cmd;
  cmd << "spinesim calibrate --level all" << (a.structured ? " --structured" : "");
  if (a.structured && (a.given("--sectors") || a.given("--rings") || a.given("--layers")))
    cmd << " --sectors " << a.structured_options.sectors << " --rings "
        << a.structured_options.rings << " --layers " << a.structured_options.layers;
  cmd << (a.cell_size_option->count() ? " --cell-size " + std::to_string(a.cell_size_mm)
                                      : std::string())
      << (a.given("--max-cell-size") ? " --max-cell-size " + fixed(a.cell_size_rule.max_mm, 2)
                                     : std::string())
      << (a.given("--cells-through-height")
              ? " --cells-through-height " + fixed(a.cell_size_rule.cells_through_height, 2)
              : std::string())
      << " --material " << a.material << " --terms "
      << (nonlinear ? term_set_name(nonlinear->terms) : a.terms) << " --train " << a.train
      << (a.holdout.empty() ? "" : " --holdout " + a.holdout);
  if (nonlinear) {
    cmd << " --nonlinear --order " << nonlinear->fem_order << " --load-levels ";
    for (std::size_t i = 0; i < nonlinear->load_levels.size(); ++i)
      cmd << (i ? "," : "") << nonlinear->load_levels[i];
    cmd << " --fibre-stretch " << a.fibre_stretch;
  } else {
    cmd << " --order " << a.order << " --check-load-scale " << rq.check_load_scale
        << (a.no_check ? " --no-check" : "");
  }
  all.generated_by = cmd.str();
  // One line on a terminal: the level being calibrated, its stage, how many are done, the ETA.
  ProgressBar bar(int(mesh::disc_levels().size()), a.quiet || a.json, "levels");
  const AllLevelsResult r = calibrate_all_levels(
      materials, all, [&bar](int done, const std::string& label) { bar.update(done, label); });
  bar.finish();
  if (!r.failed().empty()) {
    // The other levels' results are not lost: their table goes to stderr before the refusal.
    if (!a.quiet)
      print_all_levels(std::cerr, r, nonlinear ? term_set_name(nonlinear->terms) : a.terms,
                       rq.check_load_scale);
    throw std::runtime_error("Ipopt did not converge for " + r.failed() + ": no " + a.out +
                             " written");
  }
  write_json_file(a.out, calibration::to_json(r.set), 1);
  if (a.json) {
    nlohmann::json j = calibration::to_json(r.set);
    j["out"] = a.out;
    print_json(j);
    return;
  }
  print_all_levels(std::cout, r, nonlinear ? term_set_name(nonlinear->terms) : a.terms,
                   rq.check_load_scale);
  std::cout << "\nwrote " << a.out << "\n";
}

/// The options that say what to calibrate and where to write it, checked before any work.
void check_files_and_modes(const CalibrateArgs& a) {
  if (a.out.empty()) throw std::invalid_argument("--out tuned.json is required");
  if (a.mesh_path.empty() == a.level.empty())
    throw std::invalid_argument("give exactly one of --mesh and --level");
  if (a.structured && a.level.empty())
    throw std::invalid_argument("--structured meshes a level: give --level, not --mesh");
  if (a.structured && a.cell_size_option->count())
    throw std::invalid_argument("--cell-size is the CGAL mesher's: --structured takes none");
  if (!a.structured && (a.given("--sectors") || a.given("--rings") || a.given("--layers")))
    throw std::invalid_argument(
        "--sectors, --rings and --layers size the structured disc: add "
        "--structured");
  if (a.structured) mesh::validate(a.structured_options);
  if (a.order != 1 && a.order != 2) throw std::invalid_argument("--order must be 1 or 2");
  if (!(a.cell_size_mm > 0)) throw std::invalid_argument("--cell-size must be > 0 mm");
  const bool rule_given = a.given("--max-cell-size") || a.given("--cells-through-height");
  if (rule_given && (a.level != "all" || a.structured || a.cell_size_option->count()))
    throw std::invalid_argument(
        "--max-cell-size and --cells-through-height size each level's CGAL disc with --level "
        "all and no --cell-size");
  calibration::validate(a.cell_size_rule);
  if (a.level == "all" && !a.transfer_meshes.empty())
    throw std::invalid_argument(
        "--transfer-mesh is one disc's: with --level all each level is checked at 1.5x its cell "
        "size");
  if (a.level == "all" && a.per_spring)
    throw std::invalid_argument(
        "--per-spring fits one mesh: --level all writes region-level scales, which transfer to "
        "other meshes");
  if (!a.per_spring &&
      (a.smoothness_option->count() ||
       a.per_spring_max_iterations != calibration::per_spring_ipopt_defaults().max_iterations))
    throw std::invalid_argument(
        "--smoothness and --per-spring-max-iterations go with --per-spring");
  if (a.nonlinear) {
    for (const char* linear_only :
         {"--per-spring", "--transfer-mesh", "--check-load-scale", "--no-check",
          "--reaction-weight", "--stiffness-weight", "--regularisation"})
      if (a.given(linear_only))
        throw std::invalid_argument(std::string(linear_only) +
                                    " belongs to the linear calibration, not to --nonlinear");
  } else {
    for (const char* nonlinear_only : {"--load-levels", "--fibre-stretch"})
      if (a.given(nonlinear_only))
        throw std::invalid_argument(std::string(nonlinear_only) + " goes with --nonlinear");
  }
  require_output_folder(a.out, "--out");
  if (!a.mesh_path.empty() && std::filesystem::exists(a.out) &&
      std::filesystem::exists(a.mesh_path) && std::filesystem::equivalent(a.out, a.mesh_path))
    throw std::invalid_argument("--out " + a.out + " is the input mesh: give another file");
}

/// --nonlinear: the request from the linear one's cases and the nonlinear options (--order and
/// --terms default to 1 and all there, as `study mss-fibres`).
calibration::NonlinearCalibrationRequest nonlinear_request(const CalibrateArgs& a,
                                                           const CalibrationRequest& rq) {
  calibration::NonlinearCalibrationRequest n;
  n.train = rq.train;
  n.holdout = rq.holdout;
  n.load_levels = a.load_levels;
  n.fem_order = a.given("--order") ? a.order : 1;
  n.terms = a.given("--terms") ? rq.terms : TermSet::all;
  n.isochoric_fibres = a.fibre_stretch == "isochoric";
  n.fit.lower_scale = a.ipopt.lower_scale;
  n.fit.upper_scale = a.ipopt.upper_scale;
  if (a.given("--max-iterations")) n.fit.fit.ipopt.max_iterations = a.ipopt.max_iterations;
  calibration::validate(n);
  return n;
}

/// Writes the tuned file when `success`; returns what --json prints: the file's contents, the
/// mesh it was read from and (when written) where it went.
nlohmann::json write_tuned_file(const CalibrateArgs& a, const calibration::TunedDisc& tuned,
                                bool success) {
  nlohmann::json j = calibration::to_json(tuned);
  j["mesh_file"] = a.mesh_path.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.mesh_path);
  if (success) {
    write_json_file(a.out, calibration::to_json(tuned));
    j["out"] = a.out;
  }
  return j;
}

/// One disc against the nonlinear FEM; the file only when Ipopt succeeded.
void run_nonlinear(const CalibrateArgs& a, const calibration::NonlinearCalibrationRequest& rq,
                   const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                   const StatusLine& status) {
  const calibration::NonlinearCalibrationOutcome o =
      calibration::calibrate_disc_nonlinear(m, materials, rq, status);
  const nlohmann::json j = write_tuned_file(a, o.tuned, o.success);
  if (a.json)
    print_json(j);
  else
    print_nonlinear_calibration(std::cout, o);
  if (!o.success)
    throw std::runtime_error("Ipopt did not converge (" + o.fit.fit.status + " after " +
                             std::to_string(o.fit.fit.iterations) + " iterations): no " + a.out +
                             " written");
  if (!a.json) std::cout << "\nwrote " << a.out << "\n";
}

void run_calibrate(const CalibrateArgs& a) {
  // 1. Everything checked before the work starts.
  check_files_and_modes(a);
  CalibrationRequest rq;
  rq.train = fem::parse_load_cases(a.train);
  rq.holdout = a.holdout.empty()     ? calibration::held_out_cases(rq.train)
               : a.holdout == "none" ? std::vector<fem::LoadCase>()
                                     : fem::parse_load_cases(a.holdout);
  // calibrate_disc checks it too, but only after meshing (17 times for --level all).
  calibration::check_cases(rq.train, rq.holdout);
  rq.fem_order = a.order;
  rq.terms = parse_term_set(a.terms);
  rq.weights = a.weights;
  for (const double w : {a.weights.reaction, a.weights.stiffness, a.weights.regularisation})
    if (!std::isfinite(w) || w < 0)
      throw std::invalid_argument(
          "--reaction-weight, --stiffness-weight and --regularisation must be finite and >= 0");
  rq.ipopt = a.ipopt;
  rq.nonlinear_check = !a.no_check;
  if (!std::isfinite(a.check_load_scale) || a.check_load_scale <= 0)
    throw std::invalid_argument("--check-load-scale must be a finite number > 0");
  rq.check_load_scale = a.check_load_scale;
  calibration::validate(rq.ipopt);
  rq.per_spring = a.per_spring;
  rq.per_spring_weights = a.per_spring_weights;
  if (!std::isfinite(rq.per_spring_weights.smoothness) || rq.per_spring_weights.smoothness < 0)
    throw std::invalid_argument("--smoothness must be a finite number >= 0");
  rq.per_spring_ipopt.max_iterations = a.per_spring_max_iterations;
  calibration::validate(rq.per_spring_ipopt);
  const auto materials = mesh::load_material(a.material, data_dir());
  std::optional<calibration::NonlinearCalibrationRequest> nonlinear;
  if (a.nonlinear) nonlinear = nonlinear_request(a, rq);

  const bool chatty = !a.quiet && !a.json && isatty(STDERR_FILENO);
  const auto status = [chatty](const std::string& s) {
    if (chatty) std::cerr << "  " << s << std::endl;
  };
  if (a.level == "all") return run_all_levels(a, rq, nonlinear, materials);

  // 2. The mesh: read, or the level's parametric disc; and the transfer meshes.
  for (const std::string& path : a.transfer_meshes) {
    status("reading transfer mesh " + path);
    rq.transfer_meshes.emplace_back(path, mesh::read_tet_mesh(path));
  }
  mesh::TetMesh m;
  if (!a.mesh_path.empty()) {
    status("reading " + a.mesh_path);
    m = mesh::read_tet_mesh(a.mesh_path);
  } else {  // as `mesh disc --level [--structured]`
    std::optional<mesh::StructuredDiscOptions> structured;
    if (a.structured) structured = a.structured_options;
    calibration::LevelMeshes meshes = calibration::mesh_level(
        a.level, structured, a.cell_size_mm,
        !a.nonlinear && !a.no_transfer && a.transfer_meshes.empty(), data_dir(), status);
    m = std::move(meshes.mesh);
    for (auto& t : meshes.transfer) rq.transfer_meshes.push_back(std::move(t));
  }

  // 3. Calibrate, report, write only a successful result.
  if (nonlinear) return run_nonlinear(a, *nonlinear, m, materials, status);
  const CalibrationOutcome o = calibrate_disc(m, materials, rq, status);
  const nlohmann::json j = write_tuned_file(a, o.tuned, o.success);
  if (a.json)
    print_json(j);
  else
    print_calibration(std::cout, o, rq);
  if (!o.result.success)
    throw std::runtime_error("Ipopt did not converge (" + o.result.status + " after " +
                             std::to_string(o.result.iterations) + " iterations): no " + a.out +
                             " written");
  if (!o.success)
    throw std::runtime_error("per-spring stage: Ipopt did not converge (" + o.per_spring.status +
                             " after " + std::to_string(o.per_spring.iterations) +
                             " iterations; the region fit succeeded): no " + a.out + " written");
  if (!a.json) std::cout << "\nwrote " << a.out << "\n";
}

/// --nonlinear and the options that go with it.
void add_nonlinear_options(CLI::App* cmd, CalibrateArgs& args) {
  CalibrateArgs* a = &args;
  cmd->add_flag("--nonlinear", a->nonlinear,
                "Fit to the nonlinear FEM disc (tension-only fibres, finite strain) at every "
                "--load-levels, the network's plate at the FEM's pose; with a fibre material the "
                "network gets the embedded fibre elements. --order defaults to 1, --terms to all");
  cmd->add_option("--load-levels", a->load_levels,
                  "With --nonlinear: factors on the standard loads, each in (0, 2]")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--fibre-stretch", a->fibre_stretch,
                  "With --nonlinear and a fibre material: the fibre elements' stretch, isochoric "
                  "(their tet's J^(-2/3) I4, as the FEM) or spring (their own length)")
      ->check(CLI::IsMember({"spring", "isochoric"}))
      ->capture_default_str();
}

/// The CGAL cell size of --level: one size, or the per-level rule of --level all.
void add_cell_size_options(CLI::App* cmd, CalibrateArgs& args) {
  CalibrateArgs* a = &args;
  a->cell_size_option = cmd->add_option("--cell-size", a->cell_size_mm,
                                        "With --level: CGAL cell size, mm (--level all without it: "
                                        "min(2, disc height / 5) per level)")
                            ->capture_default_str();
  cmd->add_option("--max-cell-size", a->cell_size_rule.max_mm,
                  "--level all: the largest cell, mm (each level: min(this, height / "
                  "--cells-through-height))")
      ->capture_default_str();
  cmd->add_option("--cells-through-height", a->cell_size_rule.cells_through_height,
                  "--level all: cells through each disc's height (at most --max-cell-size each)")
      ->capture_default_str();
}

}  // namespace

void register_calibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Tune the mass-spring disc's stiffness to the FEM with Ipopt; writes tuned.json");
  cmd->add_option("--mesh", a->mesh_path, "Disc mesh (VTU with endplate labels)");
  cmd->add_option("--level", a->level,
                  "Or mesh this level's parametric disc (T1-T2 ... L5-S1); `all`: every level into "
                  "one tuned-set file "
                  "(as data/tuned_discs.json)");
  add_cell_size_options(cmd, *a);
  cmd->add_option(
         "--material", a->material,
         "Preset (real-disc, annulus-nucleus, fibre-reinforced, rubber, polyethylene) or JSON "
         "file")
      ->capture_default_str();
  cmd->add_option("--train", a->train, "Load cases to fit (comma-separated, or all)")
      ->capture_default_str();
  cmd->add_option("--holdout", a->holdout,
                  "Load cases only reported (default: every other case; none)");
  cmd->add_option(
         "--terms", a->terms,
         "Tuned terms, each per region: thesis (main, radial, torsion springs), thesis+volume "
         "(+ per-tet volume term), all (+ whole-disc volume term)")
      ->capture_default_str();
  cmd->add_option("--order", a->order, "FEM reference order, 1 or 2")->capture_default_str();
  cmd->add_option("--reaction-weight", a->weights.reaction, "w_r: reaction-wrench error weight")
      ->capture_default_str();
  cmd->add_option("--stiffness-weight", a->weights.stiffness,
                  "w_k: 6x6 diagonal (log ratio) weight")
      ->capture_default_str();
  cmd->add_option("--regularisation", a->weights.regularisation,
                  "w_p: pull of ln(scale) towards 0 (Van Gelder)")
      ->capture_default_str();
  cmd->add_option("--lower-scale", a->ipopt.lower_scale, "Lower bound of every scale (> 0)")
      ->capture_default_str();
  cmd->add_option("--upper-scale", a->ipopt.upper_scale, "Upper bound of every scale")
      ->capture_default_str();
  cmd->add_option("--max-iterations", a->ipopt.max_iterations, "Ipopt iteration limit")
      ->capture_default_str();
  cmd->add_option("--check-load-scale", a->check_load_scale,
                  "Nonlinear check at the case loads x this factor (linear regime; 1 = the "
                  "standard 7.5 N·m / 500 N loads)")
      ->capture_default_str();
  cmd->add_option("--transfer-mesh", a->transfer_meshes,
                  "Also check the tuned scales on this mesh of the same disc (repeatable; with "
                  "--level the default is "
                  "the same disc at 1.5x the cell size)");
  cmd->add_flag("--structured", a->structured,
                "With --level: calibrate the level's structured disc (12 sectors x 3 rings x 2 "
                "layers, as `mesh disc --structured`: the mesh the spine's offline discs simulate; "
                "its second resolution has 4 more sectors)");
  cmd->add_option("--sectors", a->structured_options.sectors,
                  "With --structured: samples around the outline (>= 6)")
      ->capture_default_str();
  cmd->add_option("--rings", a->structured_options.rings,
                  "With --structured: point rings, rim and nucleus boundary included (>= 2)")
      ->capture_default_str();
  cmd->add_option("--layers", a->structured_options.layers,
                  "With --structured: tet layers through the height (>= 1)")
      ->capture_default_str();
  cmd->add_flag("--no-transfer", a->no_transfer, "With --level: skip the second-resolution check");
  cmd->add_flag("--per-spring", a->per_spring,
                "After the region fit, one stiffness multiplier per main spring "
                "(smoothness-regularised; Ipopt "
                "limited-memory BFGS); the file then applies to this mesh only");
  a->smoothness_option = cmd->add_option("--smoothness", a->per_spring_weights.smoothness,
                                         "With --per-spring: w_s, weight of mean (ln mu_e - ln "
                                         "mu_f)^2 over springs sharing a tetrahedron")
                             ->capture_default_str();
  cmd->add_option("--per-spring-max-iterations", a->per_spring_max_iterations,
                  "With --per-spring: its Ipopt iteration limit")
      ->capture_default_str();
  cmd->add_flag("--no-check", a->no_check,
                "Skip the nonlinear MSS-vs-FEM check (errors then linearised only)");
  add_nonlinear_options(cmd, *a);
  cmd->add_option("--out", a->out, "Tuned parameter file to write (JSON); required");
  add_output_flags(cmd, a->json, a->quiet, "the tuned file\'s contents as JSON");
  cmd->footer(
      "Objective (training cases): mean relative nodal displacement error^2 + w_r reaction error^2 "
      "under\n"
      "the FEM's plate motion + w_k mean ln^2(K6_ii MSS/FEM) + w_p mean ln^2(scale), the MSS "
      "linearised at\n"
      "rest; exact adjoint gradient. Reported: untuned (Van Gelder) and tuned errors on training "
      "and\n"
      "held-out cases by the nonlinear MSS at the case loads x --check-load-scale (as `spinesim "
      "mss compare\n"
      "--load-scale`; the FEM is linear, the standard loads turn the plate by up to 15 deg on "
      "L4-L5 and ~20 deg\n"
      "on thoracic discs), beside the linearised errors. A failed Ipopt run exits 1 and writes no "
      "file.\n"
      "--per-spring: then q_e = ln mu_e per main spring, J + w_s smoothness + w_p mean q^2, mu in "
      "[0.1, 10]; the\n"
      "region-only fit is reported beside it, transfer meshes get the region-level scales "
      "(per-spring ones do not\n"
      "transfer), and the file (kind per-spring) is written only when both stages succeed.");
  a->cmd = cmd;
  cmd->callback([a] { run_calibrate(*a); });
}

}  // namespace spinesim::cli
