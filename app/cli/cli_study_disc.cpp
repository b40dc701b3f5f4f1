// spinesim study disc-validation — the FEM disc beside in-vitro disc tests.
//
//   spinesim study disc-validation [--level L4-L5] [--material fibre-reinforced]
//       [--formulation mixed] [--mesh disc.vtu] [--cell-size 2] [--csv FILE] [--json]
//       [--annulus-E MPa] [--fibre-scale F] [--nucleus-E MPa]
//       [--model nonlinear [--order 1] [--fibre-k2 K2] [--preload N] [--increments 10]
//        [--paths FILE]]
//       [--out DIR]
#include "cli_common.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/disc_identification.hpp"
#include "spinesim/studies/disc_validation.hpp"
#include "spinesim/studies/fem_reference.hpp"

#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace spinesim::cli {
namespace {

struct DiscValidationArgs {
  std::string level = "L4-L5", mesh_path, material = "fibre-reinforced", formulation = "mixed",
              targets, csv, model = "linear", paths, out;
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  studies::NonlinearDiscOptions nonlinear;
  /// The identified parameters (studies::disc_parameters) set one by one; unset: the material's.
  std::optional<double> annulus_e, fibre_scale, nucleus_e;
  bool json = false, quiet = false, markdown = false;
  bool formulation_given = false, nonlinear_flag_given = false;
};

/// --out: the JSON, the comparison and (nonlinear) the paths as CSV, then the figure and
/// report.html (scripts/disc_report.py).
void write_out_folder(const std::string& out, const DiscValidationResult& r) {
  namespace fs = std::filesystem;
  output::write_json_file((fs::path(out) / "disc_validation.json").string(),
                          disc_validation_json(r));
  std::ostringstream rows, paths;
  write_disc_validation_csv(rows, r);
  output::write_csv_file((fs::path(out) / "disc_validation.csv").string(), rows.str());
  if (!r.paths.empty()) {
    write_disc_paths_csv(paths, r);
    output::write_csv_file((fs::path(out) / "disc_paths.csv").string(), paths.str());
  }
  const output::HtmlReport report = output::write_html_report(out, "disc_report.py");
  if (report.failed) throw std::runtime_error("--out " + out + ": " + report.message);
  std::cerr << (report.written ? "" : "spinesim: warning: ") << report.message << std::endl;
}

/// The material with --annulus-E, --fibre-scale and --nucleus-E applied (the parameters the
/// identification fits; a sweep varies them), named after what changed.
mesh::RegionMaterials with_parameters(const mesh::RegionMaterials& base,
                                      const DiscValidationArgs& a) {
  if (!a.annulus_e && !a.fibre_scale && !a.nucleus_e) return base;
  const std::vector<std::pair<const char*, std::optional<double>>> given = {
      {"--annulus-E", a.annulus_e}, {"--fibre-scale", a.fibre_scale}, {"--nucleus-E", a.nucleus_e}};
  for (const auto& [flag, v] : given)
    if (v && !(std::isfinite(*v) && *v > 0 && *v < 1e5))
      throw std::invalid_argument(std::string(flag) + " must be a finite number > 0 (and < 1e5)");
  std::vector<studies::DiscParameter> parameters;
  try {
    parameters = studies::disc_parameters(base);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument(
        "--annulus-E, --fibre-scale and --nucleus-E need a material with a fibre-reinforced "
        "annulus and a nucleus; '" +
        base.name + "' is not one");
  }
  Eigen::VectorXd p(Eigen::Index(parameters.size()));
  for (std::size_t i = 0; i < parameters.size(); ++i) p(Eigen::Index(i)) = parameters[i].fit.start;
  std::string name = base.name + " with";
  auto set = [&](Eigen::Index i, const std::optional<double>& v, const std::string& what) {
    if (!v) return;
    p(i) = *v;
    name += (name.back() == 'h' ? " " : ", ") + what + " " + significant(*v, 4);
  };
  set(0, a.annulus_e, "annulus E (MPa)");
  set(1, a.fibre_scale, "fibre moduli ×");
  set(3, a.nucleus_e, "nucleus E (MPa)");
  return studies::disc_material_at(base, p, name);
}

void run_disc_validation(const DiscValidationArgs& a) {
  // 1. Every option checked before any work.
  if (a.model != "linear" && a.model != "nonlinear")
    throw std::invalid_argument("--model must be linear or nonlinear, not '" + a.model + "'");
  const bool nonlinear = a.model == "nonlinear";
  if (nonlinear && a.formulation_given)
    throw std::invalid_argument(
        "--formulation is for --model linear (the nonlinear disc takes "
        "its volume by --order)");
  if (!nonlinear && a.nonlinear_flag_given)
    throw std::invalid_argument(
        "--order, --fibre-k2, --preload, --increments and --paths need --model nonlinear");
  const fem::Formulation formulation = parse_formulation(a.formulation);
  if (nonlinear) {
    if (a.nonlinear.order != 1 && a.nonlinear.order != 2)
      throw std::invalid_argument("--order must be 1 or 2");
    if (a.nonlinear.fibre_k2 &&
        !(std::isfinite(*a.nonlinear.fibre_k2) && *a.nonlinear.fibre_k2 >= 0))
      throw std::invalid_argument("--fibre-k2 must be a finite number >= 0");
    if (a.nonlinear.load_increments < 1 || a.nonlinear.load_increments > 1000)
      throw std::invalid_argument("--increments must be 1 to 1000");
    if (!std::isfinite(a.nonlinear.preload_n) || a.nonlinear.preload_n < 0 ||
        a.nonlinear.preload_n > 1e4)
      throw std::invalid_argument("--preload: the preload must be 0 to 10000 N");
  }
  const mesh::RegionMaterials materials =
      with_parameters(mesh::load_material(a.material, data_dir()), a);
  const std::string targets_path =
      a.targets.empty() ? data_dir() + "/validation/disc_in_vitro.json" : a.targets;
  const nlohmann::json targets = read_disc_targets(targets_path);
  if (a.mesh_path.empty()) {
    mesh::disc_dimensions(a.level, data_dir());  // throws for an unknown level
    if (!std::isfinite(a.cell_size_mm) || a.cell_size_mm <= 0)
      throw std::invalid_argument("--cell-size must be a finite number > 0 mm");
  }
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");
  if (!a.paths.empty()) require_output_folder(a.paths, "--paths");
  if (!a.out.empty()) output::prepare_output_folder(a.out, "--out");

  // 2. The disc, then the study (studies/disc_validation.hpp).
  Progress progress(nonlinear ? 6 : 2, a.quiet || a.json);
  mesh::TetMesh m;
  std::string label;
  if (!a.mesh_path.empty()) {
    progress.begin("reading " + a.mesh_path);
    m = mesh::read_tet_mesh(a.mesh_path);
    mesh::require_endplate_labels(m);
    label = a.mesh_path;
  } else {
    progress.begin("meshing the " + a.level + " disc");
    m = mesh::mesh_disc_level(a.level, a.cell_size_mm, data_dir());
    label = a.level + " parametric disc, cell size " + std::to_string(a.cell_size_mm).substr(0, 4) +
            " mm";
  }
  progress.end(std::to_string(m.num_tets()) + " tets");
  const DiscValidationResult r =
      nonlinear ? studies::run_nonlinear_disc_validation(m, materials, a.nonlinear, targets, label,
                                                         progress.hooks())
                : studies::run_disc_validation(m, materials, formulation, targets, label,
                                               progress.hooks());

  // 3. Output.
  if (!a.csv.empty()) {
    std::ostringstream rows;
    write_disc_validation_csv(rows, r);
    output::write_csv_file(a.csv, rows.str());
  }
  if (!a.paths.empty()) {
    std::ostringstream rows;
    write_disc_paths_csv(rows, r);
    output::write_csv_file(a.paths, rows.str());
  }
  if (!a.out.empty()) write_out_folder(a.out, r);
  if (a.json)
    print_json(disc_validation_json(r));
  else
    print_disc_validation(std::cout, r, a.markdown);
}

}  // namespace

void register_disc_validation(CLI::App& study) {
  auto a = std::make_shared<DiscValidationArgs>();
  auto* cmd = study.add_subcommand(
      "disc-validation",
      "The FEM disc's stiffness under the standard loads and its nucleus pressure beside "
      "published in-vitro tests (MATCH / MISS)");
  cmd->add_option("--level", a->level, "Disc level, meshed in-process")->capture_default_str();
  cmd->add_option("--mesh", a->mesh_path, "Or this disc mesh (VTU with endplate labels)");
  cmd->add_option("--cell-size", a->cell_size_mm, "Mesh cell size, mm")->capture_default_str();
  cmd->add_option("--material", a->material, "Preset or JSON file")->capture_default_str();
  cmd->add_option("--formulation", a->formulation,
                  "mixed (Taylor-Hood P2-P1: gives the nucleus pressure) or displacement (P2)")
      ->capture_default_str()
      ->each([a](const std::string&) { a->formulation_given = true; });
  cmd->add_option_function<double>(
      "--annulus-E", [a](double v) { a->annulus_e = v; },
      "The annulus matrix's Young's modulus, MPa (default: the material's; the identification "
      "searches 1.0-4.2)");
  cmd->add_option_function<double>(
      "--fibre-scale", [a](double v) { a->fibre_scale = v; },
      "Multiplies the annulus fibres' moduli, inner and outer (default 1; the identification "
      "searches 0.5-2)");
  cmd->add_option_function<double>(
      "--nucleus-E", [a](double v) { a->nucleus_e = v; },
      "The nucleus's Young's modulus, MPa (default: the material's; the identification searches "
      "0.72-1.26)");
  cmd->add_option("--model", a->model,
                  "linear (the linear FEM) or nonlinear (tension-only fibres, finite strain, "
                  "the plate loaded and free)")
      ->capture_default_str();
  const auto nonlinear_flag = [a](const std::string&) { a->nonlinear_flag_given = true; };
  cmd->add_option("--order", a->nonlinear.order,
                  "Nonlinear disc: 1 (P1, nodal-average volume) or 2 (P2, mean dilatation)")
      ->capture_default_str()
      ->each(nonlinear_flag);
  cmd->add_option_function<double>(
      "--fibre-k2",
      [a](double k2) {
        a->nonlinear.fibre_k2 = k2;
        a->nonlinear_flag_given = true;
      },
      "Nonlinear disc: the fibres' toe exponent k2 (default: the material's \"k2\", else 10; "
      "k1 = k/4 of the preset)");
  cmd->add_option("--preload", a->nonlinear.preload_n,
                  "Nonlinear disc: axial compression (N) applied with each moment, the rotation "
                  "measured from the preloaded state")
      ->capture_default_str()
      ->each(nonlinear_flag);
  cmd->add_option("--increments", a->nonlinear.load_increments,
                  "Nonlinear disc: load increments, the points of each path")
      ->capture_default_str()
      ->each(nonlinear_flag);
  cmd->add_option("--paths", a->paths,
                  "Nonlinear disc: write each case's load-motion path (moment-rotation) as CSV")
      ->each(nonlinear_flag);
  cmd->add_option("--targets", a->targets,
                  "In-vitro targets file (default: data/validation/disc_in_vitro.json)");
  cmd->add_option("--csv", a->csv, "Write the comparison as CSV");
  cmd->add_option("--out", a->out,
                  "Write the JSON, CSV, the load paths' figure and report.html into this folder");
  cmd->add_flag("--markdown", a->markdown, "Print the table as markdown");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary");
  cmd->footer(
      "Loads (fem/load_cases.hpp, disc frame): compression 500 N; flexion, extension, lateral "
      "bending and\n"
      "torsion 7.5 N·m; inferior endplate fixed, superior endplate a rigid plate about the mean "
      "of its nodes.\n"
      "Stiffness = load / plate motion along it (kN/mm, N·m/deg). Nucleus pressure ratio = "
      "volume-mean\n"
      "nucleus pressure / (500 N / A), A = mesh volume / disc height (mixed formulation or the "
      "nonlinear disc).\n"
      "The nonlinear disc: secant stiffness at the standard load; a case that does not converge "
      "gives no number.");
  cmd->callback([a] { run_disc_validation(*a); });
}

}  // namespace spinesim::cli
