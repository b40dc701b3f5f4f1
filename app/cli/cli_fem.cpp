// spinesim fem — the linear FEM reference on a disc mesh.
//
//   spinesim fem --mesh disc.vtu --material real-disc --order 2 --motion 0,-0.1,0,0,0,0
//   spinesim fem --mesh disc.vtu --wrench 0,-500,0,0,0,0 --out result.vtu --json
//   spinesim fem --mesh disc.vtu --case flexion
//
// Inferior endplate (surface 1) fixed; superior endplate (surface 2) a rigid plate moved by
// --motion (mm, degrees) or loaded by --wrench (N, N·mm) about --center (default: mean of the
// superior endplate nodes). --case applies a named load case in the disc's own frame. Prints
// the reaction wrench, the plate motion and the 6x6 disc stiffness; writes the displacement
// field (mm) as VTU point data, with the pressure (MPa, --formulation mixed) and the annulus
// fibre field as cell vectors (fibre-reinforced materials).
#include "cli_common.hpp"

#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/nonlinear_fem_run.hpp"

#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct FemArgs {
  std::string mesh_path, material = "real-disc", motion, wrench, load_case, center, out;
  std::string formulation = "displacement";
  int order = 2;
  bool nonlinear = false;
  int increments = 10;
  bool json = false, quiet = false;
};

/// The solve `a` asks for, every option checked before any work.
FemRunRequest fem_request(const FemArgs& a) {
  const int loads = int(!a.motion.empty()) + int(!a.wrench.empty()) + int(!a.load_case.empty());
  if (loads > 1) throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  FemRunRequest rq;
  rq.order = a.order;
  rq.formulation = parse_formulation(a.formulation);
  if (rq.formulation == fem::Formulation::mixed && a.order != 2)
    throw std::invalid_argument("--formulation mixed is Taylor-Hood P2-P1: it needs --order 2");
  if (!a.motion.empty())
    rq.motion =
        motion_deg_to_rad(parse_numbers(a.motion, 6, "--motion tx,ty,tz,rx,ry,rz (mm, deg)"));
  if (!a.wrench.empty())
    rq.wrench = parse_numbers(a.wrench, 6, "--wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm)");
  if (!a.load_case.empty()) rq.load_case = &fem::load_case(a.load_case);
  if (!a.center.empty())
    rq.center = Eigen::Vector3d(parse_numbers(a.center, 3, "--center x,y,z (mm)"));
  return rq;
}

/// `fem --nonlinear`: the nonlinear disc under the one load, its fields to --out.
void run_nonlinear(const FemArgs& a, const FemRunRequest& rq) {
  const auto materials = mesh::load_material(a.material, data_dir());
  if (!a.out.empty()) require_output_folder(a.out, "--out");
  Progress progress(2 + int(!a.out.empty()), a.quiet || a.json);
  progress.begin("reading " + a.mesh_path);
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  progress.end(std::to_string(m.num_tets()) + " tets");
  const NonlinearFemRun r = run_nonlinear_fem(m, materials, rq, a.increments, progress.hooks());
  if (!a.out.empty()) {
    progress.begin("writing " + a.out);
    write_nonlinear_fem_vtu(a.out, m, r);
    progress.end();
  }
  nlohmann::json j = nonlinear_fem_json(r, a.mesh_path, materials.name);
  if (!a.out.empty()) j["out"] = a.out;
  if (a.json) {
    print_json(j);
    return;
  }
  const auto q = motion_rad_to_deg(r.solution.plate_motion);
  const auto& w = r.solution.reaction_wrench;
  std::cout << std::setprecision(5) << "Nonlinear disc P" << r.order << " (" << r.volumetric_form
            << ") on " << a.mesh_path << " (" << m.num_tets() << " tets, " << r.dofs
            << " DOF), material " << materials.name << ", fibre k2 " << r.fibre_k2 << "\n"
            << "  plate motion  t = " << q.head<3>().transpose()
            << " mm, r = " << q.tail<3>().transpose() << " deg\n"
            << "  reaction      F = " << w.head<3>().transpose()
            << " N, M = " << w.tail<3>().transpose() << " N·mm\n"
            << "  fields        max von Mises " << j["fields"]["max_von_mises_mpa"].get<double>()
            << " MPa, max fibre stretch " << j["fields"]["max_fibre_stretch"].get<double>()
            << ", volume ratio >= " << j["fields"]["min_volume_ratio"].get<double>() << "\n"
            << "  Newton        " << r.solution.body.newton_iterations << " iterations in "
            << r.load_increments << " increments, " << std::setprecision(3) << r.seconds << " s\n";
}

void run_fem(const FemArgs& a) {
  // 1. Every option parsed before any work: bad input fails fast, nothing is written.
  const FemRunRequest rq = fem_request(a);
  if (a.nonlinear) return run_nonlinear(a, rq);
  const auto materials = mesh::load_material(a.material, data_dir());
  if (!a.out.empty()) require_output_folder(a.out, "--out");  // a device or FIFO before the solve

  // 2. The mesh, then the driver (studies/fem_reference.hpp).
  Progress progress(3 + int(!a.out.empty()), a.quiet || a.json);
  progress.begin("reading " + a.mesh_path);
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  mesh::require_endplate_labels(m);
  progress.end(std::to_string(m.num_tets()) + " tets");
  const FemRunResult r = run_fem_reference(m, materials, rq, progress.hooks());

  // 3. Files and report.
  if (!a.out.empty()) {
    progress.begin("writing " + a.out);
    write_fem_vtu(a.out, m, r);
    progress.end();
  }
  nlohmann::json j = fem_run_json(r, a.mesh_path);
  if (!a.out.empty()) j["out"] = a.out;
  if (a.json)
    print_json(j);
  else
    print_fem_run(std::cout, r, a.mesh_path);
}

/// `export --format febio`: the .feb file and its summary.
void run_febio_export(const FemArgs& a, const FemRunRequest& rq,
                      const mesh::RegionMaterials& materials, const mesh::TetMesh& m) {
  const FebioExport e = export_febio_deck(
      a.out, m, materials, rq, m.source + ", material " + materials.name + " (spinesim export)");
  nlohmann::json j = {{"out", a.out},
                      {"format", "febio"},
                      {"element", e.element},
                      {"tets", m.num_tets()},
                      {"material", materials.name},
                      {"load", "motion"},
                      {"load_value", to_json(Eigen::VectorXd(motion_rad_to_deg(e.motion)))},
                      {"load_units", "tx,ty,tz [mm], rx,ry,rz [deg]"},
                      {"plate_center_mm", to_json(Eigen::VectorXd(e.center))}};
  if (e.solved) {
    j["motion_solved_for_wrench"] = to_json(Eigen::VectorXd(e.from_wrench));
    j["wrench_units"] = "Fx,Fy,Fz [N], Mx,My,Mz [N·mm]";
  }
  if (a.json) {
    print_json(j);
    return;
  }
  std::cout << "wrote " << a.out << ": " << m.num_tets() << " " << e.element
            << " elements, material " << materials.name << ", plate motion "
            << j["load_value"].dump() << " (mm, deg)"
            << (e.solved ? ": this FEM's answer to the wrench " + j["motion_solved_for_wrench"].dump() +
                               " (N, N·mm), since FEBio needs a rigid part for a wrench"
                         : std::string())
            << "\nrun it with: febio4 -i " << a.out << "\n";
}

void run_export(const FemArgs& a, const std::string& format) {
  if (format != "abaqus" && format != "febio")
    throw std::invalid_argument("--format '" + format +
                                "' is not known (abaqus: an .inp deck CalculiX runs; febio: a "
                                ".feb file)");
  const FemRunRequest rq = fem_request(a);
  const auto materials = mesh::load_material(a.material, data_dir());
  require_output_folder(a.out, "--out");
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  if (format == "febio") return run_febio_export(a, rq, materials, m);
  const DeckExport e = export_abaqus_deck(
      a.out, m, materials, rq, m.source + ", material " + materials.name + " (spinesim export)");
  nlohmann::json j = {{"out", a.out},
                      {"format", format},
                      {"element", e.element},
                      {"tets", m.num_tets()},
                      {"material", materials.name},
                      {"load", e.load},
                      {"load_value", to_json(Eigen::VectorXd(e.load == "motion" ? motion_rad_to_deg(e.value) : e.value))},
                      {"load_units", e.load == "motion" ? "tx,ty,tz [mm], rx,ry,rz [deg]"
                                                        : "Fx,Fy,Fz [N], Mx,My,Mz [N·mm]"},
                      {"plate_center_mm", to_json(Eigen::VectorXd(e.center))}};
  if (a.json) {
    print_json(j);
    return;
  }
  std::cout << "wrote " << a.out << ": " << m.num_tets() << " " << e.element << " elements, material "
            << materials.name << ", plate " << e.load << " " << j["load_value"].dump() << " ("
            << j["load_units"].get<std::string>() << ")\n"
            << "run it with: ccx -i " << std::filesystem::path(a.out).stem().string()
            << "   (results in the .dat and .frd files beside it)\n";
}

}  // namespace

void register_export(CLI::App& app) {
  auto a = std::make_shared<FemArgs>();
  auto format = std::make_shared<std::string>("abaqus");
  auto* cmd = app.add_subcommand(
      "export", "Write the linear disc problem for another solver (abaqus: a CalculiX/Abaqus .inp "
                "deck; febio: an FEBio .feb file)");
  cmd->add_option("--format", *format,
                  "abaqus (.inp: C3D4/C3D10, materials with the fibres as per-element anisotropic "
                  "elasticity, endplates, the load) or febio (.feb, spec 4.0: tet4/tet10, each "
                  "fibre tet an orthotropic material in its fibre axes, the plate motion; a wrench "
                  "or case is written as the motion this FEM finds under it)")
      ->capture_default_str();
  cmd->add_option("--mesh", a->mesh_path, "Disc mesh (VTU with `surface` endplate labels)")->required();
  cmd->add_option("--material", a->material, "Preset or JSON file, as for `fem`")->capture_default_str();
  cmd->add_option("--order", a->order, "1 (C3D4, tet4) or 2 (C3D10, tet10)")->capture_default_str();
  add_plate_load_options(cmd, a->motion, a->wrench, a->load_case, a->center);
  cmd->add_option("--out", a->out, "The file to write (.inp or .feb)")->required();
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a, format] { run_export(*a, *format); });
}

void register_fem(CLI::App& app) {
  auto a = std::make_shared<FemArgs>();
  auto* cmd = app.add_subcommand(
      "fem", "Linear FEM reference: rigid superior plate, fixed inferior endplate");
  cmd->add_option("--mesh", a->mesh_path, "Disc mesh (VTU with `surface` endplate labels)")
      ->required();
  cmd->add_option(
         "--material", a->material,
         "Preset (real-disc, annulus-nucleus, fibre-reinforced, rubber, polyethylene) or JSON "
         "file")
      ->capture_default_str();
  cmd->add_option("--order", a->order, "Element order: 1 (P1) or 2 (P2)")->capture_default_str();
  cmd->add_option("--formulation", a->formulation,
                  "displacement, or mixed: Taylor-Hood P2-P1 displacement-pressure for a nearly "
                  "incompressible nucleus (reports its pressure)")
      ->capture_default_str();
  cmd->add_flag("--nonlinear", a->nonlinear,
                "The nonlinear disc (finite strain, tension-only fibres, nearly incompressible "
                "nucleus; P1 nodal-average or P2 mean-dilatation volume) in place of the linear one");
  cmd->add_option("--increments", a->increments, "--nonlinear: load increments (1 to 1000)")
      ->capture_default_str();
  add_plate_load_options(cmd, a->motion, a->wrench, a->load_case, a->center);
  cmd->add_option("--out", a->out, "Write the displacement field to this VTU");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run_fem(*a); });
}

}  // namespace spinesim::cli
