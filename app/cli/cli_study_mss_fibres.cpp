// spinesim study mss-fibres — the mass-spring disc, with and without fibre springs, fitted to the
// nonlinear fibre-reinforced FEM disc at two load levels (studies/mss_fibre_study.hpp).
//
//   spinesim study mss-fibres [--level L4-L5 | --mesh disc.vtu] [--material fibre-reinforced]
//       [--cell-size 3] [--fem-order 1] [--terms all] [--fibre-stretch isochoric] [--levels 0.1,1] [--train compression,shear-ap,...]
//       [--cases all] [--threads 2] [--curve-levels 0.2,...,1] [--targets FILE] [--out DIR]
//       [--json] [--quiet]
#include "cli_common.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/mss_fibre_study.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

namespace spinesim::cli {
namespace {

struct MssFibresArgs {
  std::string level = "L4-L5", mesh_path, material = "fibre-reinforced", cases = "all",
              train = "compression,shear-ap,flexion,torsion", targets, out, terms = "all",
              fibre_stretch = "isochoric";
  std::vector<double> levels{0.1, 1.0}, curve_levels{0.2, 0.4, 0.6, 0.8, 1.0};
  double cell_size_mm = 3.0;
  studies::MssFibreStudyOptions options;
  bool json = false, quiet = false;
};

void run_mss_fibres(const MssFibresArgs& a) {
  if (a.mesh_path.empty()) mesh::disc_dimensions(a.level, data_dir());  // an unknown level
  if (!std::isfinite(a.cell_size_mm) || a.cell_size_mm <= 0)
    throw std::invalid_argument("--cell-size must be a finite number > 0 mm");
  const mesh::RegionMaterials materials = mesh::load_material(a.material, data_dir());
  studies::MssFibreStudyOptions o = a.options;
  o.cases = a.cases == "all" ? fem::standard_load_cases() : fem::parse_load_cases(a.cases);
  o.train = split_list(a.train);
  o.levels = a.levels;
  o.terms = calibration::parse_term_set(a.terms);
  o.isochoric_fibres = a.fibre_stretch == "isochoric";
  o.curve_levels = a.curve_levels;
  o.targets = studies::read_disc_targets(
      a.targets.empty() ? data_dir() + "/validation/disc_in_vitro.json" : a.targets);
  studies::validate(o, materials);
  if (!a.out.empty()) output::prepare_output_folder(a.out, "--out");

  Progress progress(0, a.quiet || a.json);
  mesh::TetMesh disc;
  std::string label;
  if (!a.mesh_path.empty()) {
    progress.begin("reading " + a.mesh_path);
    disc = mesh::read_tet_mesh(a.mesh_path);
    mesh::require_endplate_labels(disc);
    label = a.mesh_path;
  } else {
    progress.begin("meshing the " + a.level + " disc at " + output::significant(a.cell_size_mm, 3) +
                   " mm");
    disc = mesh::mesh_disc_level(a.level, a.cell_size_mm, data_dir());
    label =
        a.level + " parametric disc, cell size " + output::significant(a.cell_size_mm, 3) + " mm";
  }
  progress.end(std::to_string(disc.num_tets()) + " tets");
  const studies::MssFibreStudyResult r =
      studies::run_mss_fibre_study(disc, materials, o, label, [&](const std::string& s) {
        if (!a.quiet && !a.json) std::cerr << s << std::endl;
      });
  if (!a.out.empty()) {
    namespace fs = std::filesystem;
    output::write_json_file((fs::path(a.out) / "mss_fibres.json").string(),
                            studies::mss_fibre_study_json(r));
    std::ostringstream md;
    studies::print_mss_fibre_study(md, r);
    output::write_text_file((fs::path(a.out) / "mss_fibres.md").string(),
                            md.str() + output::markdown_provenance());
    const output::HtmlReport report = output::write_html_report(a.out, "mss_fibres_report.py");
    if (report.failed) throw std::runtime_error("--out " + a.out + ": " + report.message);
    if (!a.quiet && !a.json)
      std::cerr << (report.written ? "" : "spinesim: warning: ") << report.message << std::endl;
  }
  if (a.json)
    print_json(studies::mss_fibre_study_json(r));
  else
    studies::print_mss_fibre_study(std::cout, r);
  if (!r.region.fit.success || !r.fibre.fit.success)
    throw std::runtime_error("a fit did not finish (see the table)");
}

}  // namespace

void register_mss_fibres(CLI::App& study) {
  auto a = std::make_shared<MssFibresArgs>();
  auto* cmd = study.add_subcommand(
      "mss-fibres",
      "Fit the mass-spring disc with and without fibre springs to the nonlinear fibre-reinforced "
      "FEM disc at two load levels; errors per case and level, trained and held out");
  cmd->add_option("--level", a->level, "Disc level, meshed in-process")->capture_default_str();
  cmd->add_option("--mesh", a->mesh_path, "Or this disc mesh (VTU with endplate labels)");
  cmd->add_option("--material", a->material, "Preset or JSON file with annulus fibres")
      ->capture_default_str();
  cmd->add_option("--cell-size", a->cell_size_mm, "Cell size of the meshed disc, mm")
      ->capture_default_str();
  cmd->add_option("--fem-order", a->options.fem_order,
                  "FEM reference: 1 (P1, nodal-average volume) or 2 (P2, mean dilatation)")
      ->capture_default_str();
  cmd->add_option("--levels", a->levels, "Load levels, factors on the standard loads (in (0, 2])")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option(
         "--terms", a->terms,
         "Network terms: thesis (main, radial, torsion springs), thesis+volume (+ per-tet "
         "volume term), all (+ whole-disc volume term); the fibre network adds its springs")
      ->capture_default_str();
  cmd->add_option("--fibre-stretch", a->fibre_stretch,
                  "The fibre springs' stretch: spring (their own length) or isochoric (their "
                  "tet's J^(-2/3) I4, as the FEM)")
      ->check(CLI::IsMember({"spring", "isochoric"}))
      ->capture_default_str();
  cmd->add_option("--cases", a->cases, "Load cases (comma list or 'all')")->capture_default_str();
  cmd->add_option("--train", a->train, "Training cases (comma list); the others are held out")
      ->capture_default_str();
  cmd->add_option("--increments", a->options.load_increments, "FEM load increments per case")
      ->capture_default_str();
  cmd->add_option("--threads", a->options.threads, "MSS solves side by side")
      ->capture_default_str();
  cmd->add_option("--curve-levels", a->curve_levels,
                  "Moment-rotation curves after the fits at these levels (in (0, 2])")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--targets", a->targets,
                  "In-vitro targets drawn beside the curves (default: "
                  "data/validation/disc_in_vitro.json)");
  cmd->add_option("--out", a->out,
                  "Write mss_fibres.json, mss_fibres.md, plots/mss_fibres_curves.png and "
                  "report.html into this folder");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary");
  cmd->callback([a] { run_mss_fibres(*a); });
}

}  // namespace spinesim::cli
