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
// field (mm) as VTU point data.
#include "cli_common.hpp"
#include "spinesim/studies/fem_report.hpp"

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"

#include <iomanip>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct FemArgs {
  std::string mesh_path, material = "real-disc", motion, wrench, load_case, center, out;
  int order = 2;
  bool json = false, quiet = false;
};

void run_fem(const FemArgs& a) {
  const int loads = int(!a.motion.empty()) + int(!a.wrench.empty()) + int(!a.load_case.empty());
  if (loads > 1) throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  // Parse every number before doing any work: bad input fails fast, nothing is written.
  fem::Vector6d motion_deg = fem::Vector6d::Zero(), wrench = fem::Vector6d::Zero();
  if (!a.motion.empty())
    motion_deg = parse_numbers(a.motion, 6, "--motion tx,ty,tz,rx,ry,rz (mm, deg)");
  if (!a.wrench.empty())
    wrench = parse_numbers(a.wrench, 6, "--wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm)");
  const fem::LoadCase* named = a.load_case.empty() ? nullptr : &fem::load_case(a.load_case);
  const auto materials = mesh::load_material(a.material, data_dir());

  Progress progress(3 + int(!a.out.empty()), a.quiet || a.json);
  progress.begin("reading " + a.mesh_path);
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  mesh::require_endplate_labels(m);
  progress.end(std::to_string(m.num_tets()) + " tets");
  const Eigen::Vector3d center =
      a.center.empty() ? fem::DiscFem::default_plate_center(m)
                       : Eigen::Vector3d(parse_numbers(a.center, 3, "--center x,y,z (mm)"));

  progress.begin("assembling and factorising (P" + std::to_string(a.order) + ")");
  fem::DiscFem solver(m, materials, a.order, center);
  const fem::Matrix6d& k6 = solver.stiffness_6x6();
  progress.end(std::to_string(solver.num_dofs()) + " DOF");

  progress.begin("solving");
  fem::PlateSolution sol;
  if (named) {
    wrench = fem::global_wrench(*named, m.frame);
    sol = solver.solve_wrench(wrench);
  } else if (!a.wrench.empty()) {
    sol = solver.solve_wrench(wrench);
  } else {
    sol = solver.solve_motion(motion_deg_to_rad(motion_deg));
  }
  const double solve_s = progress.end();

  if (!a.out.empty()) {
    progress.begin("writing " + a.out);
    mesh::write_vtu(a.out, m, {{"displacement", sol.displacement_mm}});
    progress.end();
  }

  const auto& t = solver.timings();
  nlohmann::json j = {
      {"mesh", a.mesh_path},
      {"nodes", m.num_vertices()},
      {"tets", m.num_tets()},
      {"order", a.order},
      {"fem_nodes", solver.num_nodes()},
      {"dofs", solver.num_dofs()},
      {"material", materials.name},
      {"plate_center", to_json(Eigen::VectorXd(center))},
      {"plate_motion", to_json(Eigen::VectorXd(motion_rad_to_deg(sol.plate_motion)))},
      {"plate_motion_units", "tx,ty,tz [mm], rx,ry,rz [deg]"},
      {"reaction_wrench", to_json(Eigen::VectorXd(sol.reaction_wrench))},
      {"reaction_wrench_units", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm] exerted by the disc on the plate"},
      {"stiffness_6x6", to_json(Eigen::MatrixXd(stiffness_per_degree(k6)))},
      {"stiffness_6x6_units", kStiffnessUnits},
      {"max_displacement_mm", sol.displacement_mm.rowwise().norm().maxCoeff()},
      {"timings",
       {{"setup_s", t.setup_s},
        {"assembly_s", t.assembly_s},
        {"analyse_s", t.analyse_s},
        {"factorise_s", t.factorise_s},
        {"stiffness_solve_s", t.solve_s},
        {"load_solve_s", solve_s}}}};
  if (named) j["case"] = named->name;
  if (!a.out.empty()) j["out"] = a.out;
  if (a.json) {
    print_json(j);
    return;
  }
  const auto q = motion_rad_to_deg(sol.plate_motion);
  std::cout << std::setprecision(5) << "FEM P" << a.order << " on " << a.mesh_path << " ("
            << m.num_tets() << " tets, " << solver.num_dofs() << " DOF), material "
            << materials.name << "\n"
            << "  plate centre  " << center.transpose() << " mm\n"
            << "  plate motion  t = " << q.head<3>().transpose()
            << " mm, r = " << q.tail<3>().transpose() << " deg\n"
            << "  reaction      F = " << sol.reaction_wrench.head<3>().transpose()
            << " N, M = " << sol.reaction_wrench.tail<3>().transpose() << " N·mm\n";
  print_stiffness(std::cout, k6);
}

}  // namespace

void register_fem(CLI::App& app) {
  auto a = std::make_shared<FemArgs>();
  auto* cmd = app.add_subcommand(
      "fem", "Linear FEM reference: rigid superior plate, fixed inferior endplate");
  cmd->add_option("--mesh", a->mesh_path, "Disc mesh (VTU with `surface` endplate labels)")
      ->required();
  cmd->add_option("--material", a->material,
                  "Preset (real-disc, annulus-nucleus, rubber, polyethylene) or JSON file")
      ->capture_default_str();
  cmd->add_option("--order", a->order, "Element order: 1 (P1) or 2 (P2)")->capture_default_str();
  add_plate_load_options(cmd, a->motion, a->wrench, a->load_case, a->center);
  cmd->add_option("--out", a->out, "Write the displacement field to this VTU");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run_fem(*a); });
}

}  // namespace spinesim::cli
