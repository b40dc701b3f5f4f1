// spinesim study disc-identify — the nonlinear disc's material identified from in-vitro tests.
//
//   spinesim study disc-identify [--level L4-L5 | --mesh disc.vtu] [--material fibre-reinforced]
//       [--cell-size 3] [--fine-cell-size 3] [--fine-order 2] [--increments 4] [--rounds 4]
//       [--threads 2] [--no-leave-one-out] [--targets FILE] [--held-out FILE] [--preset FILE] [--out DIR]
//       [--json | --markdown] [--quiet]
#include "cli_common.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/output/html_report.hpp"
#include "spinesim/studies/disc_identification.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

namespace spinesim::cli {
namespace {

struct DiscIdentifyArgs {
  std::string level = "L4-L5", mesh_path, material = "fibre-reinforced", targets, held_out, preset,
              out;
  double cell_size_mm = 3.0, fine_cell_size_mm = 3.0;
  studies::DiscIdentificationOptions options;
  bool json = false, quiet = false, markdown = false, no_leave_one_out = false;
};

std::string disc_label(const std::string& level, double cell_mm, int order) {
  std::ostringstream s;
  s << level << " parametric disc, cell size " << output::significant(cell_mm, 3) << " mm, P"
    << order << (order == 1 ? " nodal-average volume" : " mean dilatation");
  return s.str();
}

void run_disc_identify(const DiscIdentifyArgs& a) {
  // 1. Every option and file checked before any work.
  if (a.mesh_path.empty()) mesh::disc_dimensions(a.level, data_dir());  // an unknown level
  for (double c : {a.cell_size_mm, a.fine_cell_size_mm})
    if (!std::isfinite(c) || c <= 0)
      throw std::invalid_argument("--cell-size and --fine-cell-size must be finite numbers > 0 mm");
  const mesh::RegionMaterials base = mesh::load_material(a.material, data_dir());
  studies::disc_parameters(base);  // throws for a material the fit cannot move
  studies::validate(a.options);
  const nlohmann::json targets = studies::read_disc_targets(
      a.targets.empty() ? data_dir() + "/validation/disc_in_vitro.json" : a.targets);
  const nlohmann::json held_out = studies::read_disc_targets(
      a.held_out.empty() ? data_dir() + "/validation/disc_in_vitro_held_out.json" : a.held_out);
  if (!a.preset.empty()) require_output_folder(a.preset, "--preset");
  if (!a.out.empty()) output::prepare_output_folder(a.out, "--out");

  // 2. The two discs, then the identification (studies/disc_identification.hpp).
  studies::DiscIdentificationOptions options = a.options;
  options.leave_one_out = !a.no_leave_one_out;
  Progress progress(0, a.quiet || a.json);
  mesh::TetMesh coarse, fine;
  std::string coarse_label, fine_label;
  if (!a.mesh_path.empty()) {
    progress.begin("reading " + a.mesh_path);
    coarse = fine = mesh::read_tet_mesh(a.mesh_path);
    mesh::require_endplate_labels(coarse);
    coarse_label = a.mesh_path + ", P" + std::to_string(options.coarse_order);
    fine_label = a.mesh_path + ", P" + std::to_string(options.fine_order);
  } else {
    progress.begin("meshing the " + a.level + " disc at " + output::significant(a.cell_size_mm, 3) +
                   " and " + output::significant(a.fine_cell_size_mm, 3) + " mm");
    coarse = mesh::mesh_disc_level(a.level, a.cell_size_mm, data_dir());
    fine = a.fine_cell_size_mm == a.cell_size_mm
               ? coarse
               : mesh::mesh_disc_level(a.level, a.fine_cell_size_mm, data_dir());
    coarse_label = disc_label(a.level, a.cell_size_mm, options.coarse_order);
    fine_label = disc_label(a.level, a.fine_cell_size_mm, options.fine_order);
  }
  progress.end(std::to_string(coarse.num_tets()) + " and " + std::to_string(fine.num_tets()) +
               " tets");
  const studies::DiscIdentificationResult r = studies::identify_disc_material(
      coarse, fine, base, targets, held_out, options, coarse_label, fine_label, progress.hooks());

  // 3. Output: the preset only for a finished identification.
  const nlohmann::json preset = studies::identified_material_json(r, base);
  if (!a.preset.empty() && r.success) output::write_json_file(a.preset, preset);
  if (!a.out.empty()) {
    namespace fs = std::filesystem;
    output::write_json_file((fs::path(a.out) / "disc_identification.json").string(),
                            studies::disc_identification_json(r));
    std::ostringstream md;
    studies::print_disc_identification(md, r, true);
    output::write_text_file((fs::path(a.out) / "disc_identification.md").string(),
                            md.str() + output::markdown_provenance());
    if (r.success)
      output::write_json_file((fs::path(a.out) / "disc-identified.json").string(), preset);
    const output::HtmlReport report = output::write_html_report(a.out, "identify_report.py");
    if (report.failed) throw std::runtime_error("--out " + a.out + ": " + report.message);
    std::cerr << (report.written ? "" : "spinesim: warning: ") << report.message << std::endl;
  }
  if (a.json)
    print_json(studies::disc_identification_json(r));
  else
    studies::print_disc_identification(std::cout, r, a.markdown);
  if (!r.success) throw std::runtime_error("the identification did not finish: " + r.status);
}

}  // namespace

void register_disc_identify(CLI::App& study) {
  auto a = std::make_shared<DiscIdentifyArgs>();
  auto* cmd = study.add_subcommand(
      "disc-identify",
      "Identify the nonlinear disc's material (annulus matrix, fibres, nucleus) from in-vitro "
      "tests with Ipopt: fit, leave-one-out and a held-out data set");
  cmd->add_option("--level", a->level, "Disc level, meshed in-process")->capture_default_str();
  cmd->add_option("--mesh", a->mesh_path,
                  "Or this disc mesh (VTU with endplate labels), coarse and fine alike");
  cmd->add_option("--material", a->material,
                  "Starting preset or JSON file (annulus with fibres "
                  "and nucleus)")
      ->capture_default_str();
  cmd->add_option("--cell-size", a->cell_size_mm, "Coarse disc (the fits' model): cell size, mm")
      ->capture_default_str();
  cmd->add_option("--fine-cell-size", a->fine_cell_size_mm,
                  "Fine disc (the reported one): cell size, mm")
      ->capture_default_str();
  cmd->add_option("--fine-order", a->options.fine_order,
                  "Fine disc: 2 (P2, mean dilatation) or 1 (P1, nodal-average volume)")
      ->capture_default_str();
  cmd->add_option("--increments", a->options.load_increments, "Load increments per load case")
      ->capture_default_str();
  cmd->add_option("--rounds", a->options.max_mapping_rounds,
                  "Most fit rounds correcting the coarse disc toward the fine one")
      ->capture_default_str();
  cmd->add_option("--threads", a->options.threads, "Disc solves side by side")
      ->capture_default_str();
  cmd->add_flag("--no-leave-one-out", a->no_leave_one_out,
                "Skip the six fits without one quantity each (a quick run)");
  cmd->add_option("--targets", a->targets,
                  "In-vitro targets (default: data/validation/disc_in_vitro.json)");
  cmd->add_option("--held-out", a->held_out,
                  "Held-out tests (default: data/validation/disc_in_vitro_held_out.json)");
  cmd->add_option("--preset", a->preset, "Write the identified material as a preset file");
  cmd->add_option("--out", a->out,
                  "Write the JSON, the tables (markdown), the identified preset, the figure and "
                  "report.html into this folder");
  cmd->add_flag("--markdown", a->markdown, "Print the tables as markdown");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary");
  cmd->footer(
      "Residual of a quantity: ln(q / sqrt(low high)) / (ln(high / low) / 2), so |r| <= 1 inside "
      "its window;\nIpopt minimises the sum of squares over ln p within each parameter's bounds "
      "(printed with their\nsources). The fits run on the coarse disc times the fine/coarse ratio "
      "of each quantity (output\nspace mapping); every number reported is the fine disc's. Takes "
      "minutes (see docs/benchmarks.md).");
  cmd->callback([a] { run_disc_identify(*a); });
}

}  // namespace spinesim::cli
