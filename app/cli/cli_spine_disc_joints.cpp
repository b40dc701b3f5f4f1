// spinesim spine disc-joints — each level's FEM disc as the spine's joint spring.
//
//   spinesim spine disc-joints [--material fibre-reinforced] [--formulation displacement|mixed]
//       [--levels L4-L5,L5-S1] [--out data/spine/disc_joints/fibre-reinforced.json] [--json]
//   spinesim spine disc-joints --tuned shipped --out data/spine/disc_joints/tuned-mss.json
//   spinesim spine disc-joints --nonlinear [--moment N_M] [--order 1] [--cell-size MM]
#include "cli_common.hpp"
#include "spinesim/studies/disc_joints.hpp"
#include "spinesim/studies/fem_reference.hpp"

#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/spine/model.hpp"

#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct DiscJointsArgs {
  std::string material = "fibre-reinforced", formulation = "displacement", levels, out, tuned;
  bool json = false, quiet = false, nonlinear = false;
  NonlinearJointOptions nonlinear_options;
};

void run_disc_joints(const DiscJointsArgs& a) {
  const mesh::RegionMaterials materials = mesh::load_material(a.material, data_dir());
  const fem::Formulation formulation = parse_formulation(a.formulation);
  std::vector<std::string> levels;
  for (const auto& l : split_list(a.levels))
    levels.push_back(spine::joint_names()[std::size_t(spine::joint_index(l))]);
  if (!a.out.empty()) require_output_folder(a.out, "--out");
  Progress progress(levels.empty() ? int(spine::joint_names().size()) : int(levels.size()),
                    a.quiet || a.json);
  if (a.nonlinear && !a.tuned.empty())
    throw std::invalid_argument("--nonlinear and --tuned: choose one");
  const DiscJointSet set =
      a.nonlinear ? compute_nonlinear_disc_joints(data_dir(), materials, a.nonlinear_options,
                                                  levels, progress.hooks())
      : a.tuned.empty()
          ? compute_disc_joints(data_dir(), materials, formulation, levels, progress.hooks())
          : compute_tuned_disc_joints(
                data_dir(),
                a.tuned == "shipped" ? calibration::shipped_tuned_set_path(data_dir()) : a.tuned,
                levels, progress.hooks());
  const nlohmann::json j = disc_joints_json(set);
  if (!a.out.empty()) write_json_file(a.out, j, 1);
  if (a.json)
    print_json(j);
  else
    print_disc_joints(std::cout, set);
}

}  // namespace

void register_spine_disc_joints(CLI::App& spine) {
  auto a = std::make_shared<DiscJointsArgs>();
  auto* cmd = spine.add_subcommand(
      "disc-joints",
      "Each level's FEM disc as the spine's joint spring: the 3x3 rotational stiffness about the "
      "F.2 joint point (for --disc-joints)");
  cmd->add_option("--material", a->material, "Disc material preset or JSON file")
      ->capture_default_str();
  cmd->add_option("--formulation", a->formulation, "displacement (P2) or mixed (Taylor-Hood)")
      ->capture_default_str();
  cmd->add_option("--tuned", a->tuned,
                  "Use a tuned MSS set instead of the FEM (`shipped`: data/tuned_discs.json; its "
                  "own material)");
  cmd->add_flag("--nonlinear", a->nonlinear,
                "The nonlinear disc (tension-only fibres, finite strain): each direction's "
                "secant stiffness over the joint's range of motion (or at --moment)");
  cmd->add_option("--moment", a->nonlinear_options.moment_nm,
                  "--nonlinear: take the secants at this moment about the joint point (N m; "
                  "default: at the range of motion, thesis F.5)");
  cmd->add_option("--order", a->nonlinear_options.order,
                  "--nonlinear: element order, 1 (nodal-average volume) or 2 (mean dilatation)")
      ->capture_default_str();
  cmd->add_option("--cell-size", a->nonlinear_options.cell_size_mm,
                  "--nonlinear: CGAL cell size (mm; default min(2 mm, h/5) per level)");
  cmd->add_option("--levels", a->levels, "Comma-separated joints (default: all 17)");
  cmd->add_option("--out", a->out, "Write the disc-joint file (JSON)");
  add_output_flags(cmd, a->json, a->quiet, "the file's contents");
  cmd->footer(
      "Per level: the parametric disc in the spine frame (CGAL cell min(2 mm, h/5)), FEM P2 "
      "condensed onto the\n"
      "superior plate (6x6 about its centre c), then K_J = T^T K6 T with T = [-[c - J]x ; I]: "
      "rotations of the\n"
      "upper vertebra about the joint point J. Printed: the diagonal beside the thesis's F.4 "
      "springs.\n"
      "--nonlinear: the nonlinear disc turned about J in flexion, extension, lateral bending and "
      "torsion to\n"
      "the joint's range of motion (F.5), or to where the moment about J reaches --moment; the "
      "spine's bilinear\n"
      "joint gets each direction's secant, the coupling keeps the rest tangent's correlation.");
  cmd->callback([a] { run_disc_joints(*a); });
}

}  // namespace spinesim::cli
