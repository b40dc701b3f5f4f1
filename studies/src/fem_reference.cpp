#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/atomic_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/abaqus_deck.hpp"
#include "spinesim/fem/febio_deck.hpp"
#include "spinesim/mesh/io.hpp"

#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <iomanip>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::studies {

namespace {}

void print_stiffness(std::ostream& os, const fem::Matrix6d& k_rad) {
  const fem::Matrix6d k = stiffness_per_degree(k_rad);
  static const char* rows[] = {"Fx [N]", "Fy [N]", "Fz [N]", "Mx [N·mm]", "My [N·mm]", "Mz [N·mm]"};
  os << "  6x6 stiffness about the plate centre (columns: tx ty tz per mm, rx ry rz per degree)\n";
  TextTable t({"", "tx", "ty", "tz", "rx", "ry", "rz"});
  for (int i = 0; i < 6; ++i) {
    std::vector<std::string> row{rows[i]};
    for (int c = 0; c < 6; ++c) row.push_back(significant(k(i, c), 4));
    t.add(row);
  }
  t.print(os, false);
}

FemRunResult run_fem_reference(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                               const FemRunRequest& request, const StageHooks& hooks) {
  const FemRunRequest& rq = request;
  if (int(rq.motion.has_value()) + int(rq.wrench.has_value()) + int(rq.load_case != nullptr) > 1)
    throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  FemRunResult r;
  r.request = rq;
  r.material = materials.name;
  r.nodes = m.num_vertices();
  r.tets = m.num_tets();
  r.center = rq.center ? *rq.center : fem::DiscFem::default_plate_center(m);

  hooks.begin_stage(rq.formulation == fem::Formulation::mixed
                        ? std::string("assembling and factorising (Taylor-Hood P2-P1)")
                        : "assembling and factorising (P" + std::to_string(rq.order) + ")");
  fem::SolverOptions options;
  options.formulation = rq.formulation;
  fem::DiscFem solver(m, materials, rq.order, r.center, options);
  r.fibres = solver.fibres();
  r.stiffness = solver.stiffness_6x6();
  r.fem_nodes = solver.num_nodes();
  r.dofs = solver.num_dofs();
  hooks.end_stage(std::to_string(r.dofs) + " DOF");

  hooks.begin_stage("solving");
  const Timer timer;
  if (rq.load_case || rq.wrench) {
    r.applied_wrench = rq.load_case ? fem::global_wrench(*rq.load_case, m.frame) : *rq.wrench;
    r.solution = solver.solve_wrench(r.applied_wrench);
  } else {
    r.solution = solver.solve_motion(rq.motion ? *rq.motion : fem::Vector6d::Zero());
  }
  r.load_solve_s = timer.seconds();
  const bool mixed = rq.formulation == fem::Formulation::mixed;
  r.fields = fem::element_fields(m, materials, r.fibres, rq.order, r.solution.node_displacement_mm,
                                 mixed ? &r.solution.element_mean_stress_mpa : nullptr);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    r.strain_energy_mj += r.fields.strain_energy_density_mpa(t) * mesh::tet_volume(m, t);
  hooks.end_stage();
  r.timings = solver.timings();
  return r;
}

nlohmann::json fem_run_json(const FemRunResult& r, const std::string& mesh_label) {
  const auto& t = r.timings;
  const auto& sol = r.solution;
  nlohmann::json j = {
      {"mesh", mesh_label},
      {"nodes", r.nodes},
      {"tets", r.tets},
      {"order", r.request.order},
      {"fem_nodes", r.fem_nodes},
      {"dofs", r.dofs},
      {"material", r.material},
      {"plate_center", to_json(Eigen::VectorXd(r.center))},
      {"plate_motion", to_json(Eigen::VectorXd(motion_rad_to_deg(sol.plate_motion)))},
      {"plate_motion_units", "tx,ty,tz [mm], rx,ry,rz [deg]"},
      {"reaction_wrench", to_json(Eigen::VectorXd(sol.reaction_wrench))},
      {"reaction_wrench_units", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm] exerted by the disc on the plate"},
      {"stiffness_6x6", to_json(Eigen::MatrixXd(stiffness_per_degree(r.stiffness)))},
      {"stiffness_6x6_units", kStiffnessUnits},
      {"max_displacement_mm", sol.displacement_mm.rowwise().norm().maxCoeff()},
      {"timings",
       {{"setup_s", t.setup_s},
        {"assembly_s", t.assembly_s},
        {"analyse_s", t.analyse_s},
        {"factorise_s", t.factorise_s},
        {"stiffness_solve_s", t.solve_s},
        {"load_solve_s", r.load_solve_s}}}};
  if (r.request.load_case) j["case"] = r.request.load_case->name;
  j["formulation"] = formulation_name(r.request.formulation);
  if (std::isfinite(sol.nucleus_pressure_mpa)) j["nucleus_pressure_mpa"] = sol.nucleus_pressure_mpa;
  j["fibres"] = !r.fibres.empty();
  const fem::ElementFields& f = r.fields;
  j["fields"] = {{"max_von_mises_mpa", f.von_mises_mpa.maxCoeff()},
                 {"max_pressure_mpa", f.pressure_mpa.maxCoeff()},
                 {"min_pressure_mpa", f.pressure_mpa.minCoeff()},
                 {"max_principal_strain", f.principal_strain.col(0).maxCoeff()},
                 {"min_principal_strain", f.principal_strain.col(2).minCoeff()},
                 {"strain_energy_mj", r.strain_energy_mj}};
  if (!r.fibres.empty()) {
    j["fields"]["max_fibre_stress_mpa"] = f.fibre_stress_mpa.maxCoeff();
    j["fields"]["min_fibre_stress_mpa"] = f.fibre_stress_mpa.minCoeff();
  }
  j["fields_units"] = "per-tet means; MPa, strain 1, mJ (= N·mm)";
  return j;
}

fem::Formulation parse_formulation(const std::string& name) {
  if (name == "displacement") return fem::Formulation::displacement;
  if (name == "mixed") return fem::Formulation::mixed;
  throw std::invalid_argument("unknown formulation '" + name + "' (displacement, mixed)");
}

const char* formulation_name(fem::Formulation f) {
  return f == fem::Formulation::mixed ? "mixed" : "displacement";
}

FemArrays fem_run_arrays(const mesh::TetMesh& m, const FemRunResult& r) {
  std::vector<mesh::DataArray> points{{"displacement", r.solution.displacement_mm}};
  if (r.solution.pressure_mpa.size() == m.num_vertices())
    points.push_back({"pressure", r.solution.pressure_mpa});
  const fem::ElementFields& f = r.fields;
  std::vector<mesh::DataArray> cells = {
      {"stress_MPa", f.stress_mpa},  // symmetric tensors: xx yy zz xy yz xz (ParaView's order)
      {"von_mises_MPa", f.von_mises_mpa},
      {"pressure_MPa", f.pressure_mpa},
      {"strain", f.strain},
      {"principal_strain", f.principal_strain},
      {"principal_strain_direction_1", f.principal_strain_directions.leftCols(3)},
      {"principal_strain_direction_2", f.principal_strain_directions.middleCols(3, 3)},
      {"principal_strain_direction_3", f.principal_strain_directions.rightCols(3)},
      {"strain_energy_density_MPa", f.strain_energy_density_mpa}};
  if (!r.fibres.empty()) {
    cells.push_back({"fibre_stretch", f.fibre_stretch});
    cells.push_back({"fibre_stress_MPa", f.fibre_stress_mpa});
    // VTU files hold finite numbers only (io.hpp): cells without fibres get zero vectors, angle
    // 0 and depth -1 (outside [0, 1]).
    const auto finite_or = [](const Eigen::VectorXd& v, double fill) {
      return Eigen::VectorXd(v.unaryExpr([fill](double x) { return std::isfinite(x) ? x : fill; }));
    };
    cells.insert(cells.end(), {{"fibre_direction_1", r.fibres.direction_1},
                               {"fibre_direction_2", r.fibres.direction_2},
                               {"fibre_angle_deg", finite_or(r.fibres.angle_deg, 0.0)},
                               {"annulus_depth", finite_or(r.fibres.depth, -1.0)}});
  }
  return {std::move(points), std::move(cells)};
}

void write_fem_vtu(const std::string& path, const mesh::TetMesh& m, const FemRunResult& r) {
  const FemArrays a = fem_run_arrays(m, r);
  mesh::write_vtu(path, m, a.points, a.cells);
}

namespace {

/// What every export refuses: more than one load, the mixed formulation (neither CalculiX nor
/// FEBio has a Taylor-Hood P2-P1 element), a mesh without endplates.
void check_export(const mesh::TetMesh& m, const FemRunRequest& rq, const std::string& element) {
  if (int(rq.motion.has_value()) + int(rq.wrench.has_value()) + int(rq.load_case != nullptr) > 1)
    throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  if (rq.formulation == fem::Formulation::mixed)
    throw std::invalid_argument("--formulation mixed has no element in the other solver "
                                "(Taylor-Hood P2-P1); export the displacement form (" +
                                element + ")");
  mesh::require_endplate_labels(m);
}

}  // namespace

DeckExport export_abaqus_deck(const std::string& path, const mesh::TetMesh& m,
                              const mesh::RegionMaterials& materials, const FemRunRequest& rq,
                              const std::string& title) {
  check_export(m, rq, "C3D10");
  fem::AbaqusDeck deck;
  deck.order = rq.order;
  deck.title = title;
  deck.plate_center_mm = rq.center ? *rq.center : fem::DiscFem::default_plate_center(m);
  deck.prescribed_motion = !(rq.wrench || rq.load_case);
  if (rq.load_case)
    deck.load = fem::global_wrench(*rq.load_case, m.frame);
  else if (rq.wrench)
    deck.load = *rq.wrench;
  else if (rq.motion)
    deck.load = *rq.motion;
  write_atomically("export", path,
                   [&](std::ostream& os) { fem::write_abaqus_deck(os, m, materials, deck); });
  return {rq.order == 1 ? "C3D4" : "C3D10", deck.prescribed_motion ? "motion" : "wrench",
          deck.load, deck.plate_center_mm};
}

FebioExport export_febio_deck(const std::string& path, const mesh::TetMesh& m,
                              const mesh::RegionMaterials& materials, const FemRunRequest& rq,
                              const std::string& title) {
  check_export(m, rq, "tet10");
  fem::FebioDeck deck;
  deck.order = rq.order;
  deck.title = title;
  deck.plate_center_mm = rq.center ? *rq.center : fem::DiscFem::default_plate_center(m);
  FebioExport e;
  if (rq.wrench || rq.load_case) {
    // FEBio takes a wrench through a rigid body the disc mesh has not got: the file prescribes
    // the plate motion this FEM finds under the wrench, and the reactions FEBio reports on the
    // superior nodes then sum to the wrench's opposite.
    const FemRunResult r = run_fem_reference(m, materials, rq);
    deck.motion = r.solution.plate_motion;
    e.from_wrench = rq.load_case ? fem::global_wrench(*rq.load_case, m.frame) : *rq.wrench;
    e.solved = true;
  } else if (rq.motion) {
    deck.motion = *rq.motion;
  }
  write_atomically("export", path,
                   [&](std::ostream& os) { fem::write_febio_deck(os, m, materials, deck); });
  e.element = rq.order == 1 ? "tet4" : "tet10";
  e.motion = deck.motion;
  e.center = deck.plate_center_mm;
  return e;
}

void print_fem_run(std::ostream& os, const FemRunResult& r, const std::string& mesh_label) {
  const auto q = motion_rad_to_deg(r.solution.plate_motion);
  const auto& w = r.solution.reaction_wrench;
  os << std::setprecision(5) << "FEM "
     << (r.request.formulation == fem::Formulation::mixed ? std::string("Taylor-Hood P2-P1")
                                                          : "P" + std::to_string(r.request.order))
     << " on " << mesh_label << " (" << r.tets << " tets, " << r.dofs << " DOF), material "
     << r.material << (r.fibres.empty() ? "" : " (fibre-reinforced annulus)") << "\n"
     << "  plate centre  " << r.center.transpose() << " mm\n"
     << "  plate motion  t = " << q.head<3>().transpose() << " mm, r = " << q.tail<3>().transpose()
     << " deg\n"
     << "  reaction      F = " << w.head<3>().transpose() << " N, M = " << w.tail<3>().transpose()
     << " N·mm\n";
  if (std::isfinite(r.solution.nucleus_pressure_mpa))
    os << "  nucleus pressure " << r.solution.nucleus_pressure_mpa << " MPa (volume mean)\n";
  const fem::ElementFields& f = r.fields;
  os << "  stress        von Mises up to " << f.von_mises_mpa.maxCoeff() << " MPa, pressure "
     << f.pressure_mpa.minCoeff() << " .. " << f.pressure_mpa.maxCoeff() << " MPa (tet means)\n"
     << "  strain        principal " << f.principal_strain.col(2).minCoeff() << " .. "
     << f.principal_strain.col(0).maxCoeff() << ", energy " << r.strain_energy_mj << " mJ\n";
  if (!r.fibres.empty())
    os << "  fibre stress  " << f.fibre_stress_mpa.minCoeff() << " .. "
       << f.fibre_stress_mpa.maxCoeff() << " MPa\n";
  print_stiffness(os, r.stiffness);
}

}  // namespace spinesim::studies
