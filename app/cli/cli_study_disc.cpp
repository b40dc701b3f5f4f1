// spinesim study disc-validation — the FEM disc beside in-vitro disc tests.
//
//   spinesim study disc-validation [--level L4-L5] [--material fibre-reinforced]
//       [--formulation mixed] [--mesh disc.vtu] [--cell-size 2] [--csv FILE] [--json]
#include "cli_common.hpp"
#include "spinesim/mesh/disc_level.hpp"
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

namespace spinesim::cli {
namespace {

struct DiscValidationArgs {
  std::string level = "L4-L5", mesh_path, material = "fibre-reinforced", formulation = "mixed",
              targets, csv;
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  bool json = false, quiet = false, markdown = false;
};

void run_disc_validation(const DiscValidationArgs& a) {
  // 1. Every option checked before any work.
  const fem::Formulation formulation = parse_formulation(a.formulation);
  const mesh::RegionMaterials materials = mesh::load_material(a.material, data_dir());
  const std::string targets_path =
      a.targets.empty() ? data_dir() + "/validation/disc_in_vitro.json" : a.targets;
  const nlohmann::json targets = read_disc_targets(targets_path);
  if (a.mesh_path.empty()) {
    mesh::disc_dimensions(a.level, data_dir());  // throws for an unknown level
    if (!std::isfinite(a.cell_size_mm) || a.cell_size_mm <= 0)
      throw std::invalid_argument("--cell-size must be a finite number > 0 mm");
  }
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");

  // 2. The disc, then the study (studies/disc_validation.hpp).
  Progress progress(2, a.quiet || a.json);
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
      studies::run_disc_validation(m, materials, formulation, targets, label, progress.hooks());

  // 3. Output.
  if (!a.csv.empty()) {
    std::ofstream f(a.csv);
    write_disc_validation_csv(f, r);
    if (!f) throw std::runtime_error("--csv " + a.csv + ": could not write the file");
  }
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
      ->capture_default_str();
  cmd->add_option("--targets", a->targets,
                  "In-vitro targets file (default: data/validation/disc_in_vitro.json)");
  cmd->add_option("--csv", a->csv, "Write the comparison as CSV");
  cmd->add_flag("--markdown", a->markdown, "Print the table as markdown");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary");
  cmd->footer(
      "Loads (fem/load_cases.hpp, disc frame): compression 500 N; flexion, extension, lateral "
      "bending and\n"
      "torsion 7.5 N·m; inferior endplate fixed, superior endplate a rigid plate about the mean "
      "of its nodes.\n"
      "Stiffness = load / plate motion along it (kN/mm, N·m/deg). Nucleus pressure ratio = "
      "volume-mean\n"
      "nucleus pressure / (500 N / A), A = mesh volume / disc height (mixed formulation only).");
  cmd->callback([a] { run_disc_validation(*a); });
}

}  // namespace spinesim::cli
