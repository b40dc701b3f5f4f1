#include "spinesim/studies/nonlinear_fem_run.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::studies {

NonlinearFemRun run_nonlinear_fem(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                                  const FemRunRequest& rq, int load_increments,
                                  const StageHooks& hooks) {
  if (int(rq.motion.has_value()) + int(rq.wrench.has_value()) + int(rq.load_case != nullptr) > 1)
    throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  if (rq.formulation == fem::Formulation::mixed)
    throw std::invalid_argument("--nonlinear takes its own volumetric form (nodal average on P1, "
                                "mean dilatation on P2): leave out --formulation mixed");
  if (rq.order != 1 && rq.order != 2) throw std::invalid_argument("--order must be 1 or 2");
  if (load_increments < 1 || load_increments > 1000)
    throw std::invalid_argument("--increments must be 1 to 1000");
  mesh::require_endplate_labels(m);
  NonlinearFemRun r;
  r.order = rq.order;
  r.load_increments = load_increments;
  r.fibre_k2 = fem::material_fibre_k2(materials);
  r.center = rq.center ? *rq.center : fem::DiscFem::default_plate_center(m);
  hooks.begin_stage("nonlinear disc, " + std::to_string(load_increments) + " load increments");
  const Timer timer;
  const fem::NonlinearDisc disc(m, fem::disc_element_materials(m, materials, r.fibre_k2),
                                rq.order, r.center);
  r.volumetric_form = disc.body().form() == fem::VolumetricForm::nodal_average ? "nodal average"
                      : disc.body().form() == fem::VolumetricForm::mean_dilatation
                          ? "mean dilatation"
                          : "pointwise";
  r.dofs = 3 * disc.body().space().num_nodes();
  fem::NewtonOptions newton;
  newton.load_increments = load_increments;
  if (rq.wrench || rq.load_case) {
    fem::PlateLoad load;
    load.value = rq.load_case ? fem::global_wrench(*rq.load_case, m.frame) : *rq.wrench;
    r.solution = disc.solve(load, newton);
  } else {
    r.solution = disc.solve_motion(rq.motion ? *rq.motion : fem::Vector6d::Zero().eval(), newton);
  }
  if (!r.solution.body.converged)
    throw std::runtime_error("the nonlinear disc did not converge: " + r.solution.body.failure);
  const Eigen::MatrixX3d& d = r.solution.body.displacement_mm;
  Eigen::VectorXd u(3 * d.rows());
  for (Eigen::Index n = 0; n < d.rows(); ++n) u.segment<3>(3 * n) = d.row(n).transpose();
  r.fields = fem::nonlinear_element_fields(disc.body(), u);
  r.seconds = timer.seconds();
  hooks.end_stage(std::to_string(r.solution.body.newton_iterations) + " Newton iterations");
  return r;
}

nlohmann::json nonlinear_fem_json(const NonlinearFemRun& r, const std::string& mesh_label,
                                  const std::string& material) {
  const fem::NonlinearElementFields& f = r.fields;
  nlohmann::json j = {
      {"mesh", mesh_label},
      {"model", "nonlinear"},
      {"material", material},
      {"order", r.order},
      {"volumetric_form", r.volumetric_form},
      {"fibre_k2", r.fibre_k2},
      {"dofs", r.dofs},
      {"load_increments", r.load_increments},
      {"newton_iterations", r.solution.body.newton_iterations},
      {"cutbacks", r.solution.body.cutbacks},
      {"plate_center", to_json(Eigen::VectorXd(r.center))},
      {"plate_motion", to_json(Eigen::VectorXd(motion_rad_to_deg(r.solution.plate_motion)))},
      {"plate_motion_units", "tx,ty,tz [mm], rx,ry,rz [deg]"},
      {"reaction_wrench", to_json(Eigen::VectorXd(r.solution.reaction_wrench))},
      {"reaction_wrench_units", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm] exerted by the disc on the plate"},
      {"strain_energy_mj", r.solution.body.energy_mj},
      {"fields",
       {{"max_von_mises_mpa", f.von_mises_mpa.maxCoeff()},
        {"max_pressure_mpa", f.pressure_mpa.maxCoeff()},
        {"min_pressure_mpa", f.pressure_mpa.minCoeff()},
        {"max_principal_stretch", f.principal_stretch.col(0).maxCoeff()},
        {"min_principal_stretch", f.principal_stretch.col(2).minCoeff()},
        {"max_fibre_stretch", f.fibre_stretch.maxCoeff()},
        {"max_fibre_stress_mpa", f.fibre_stress_mpa.maxCoeff()},
        {"min_volume_ratio", f.volume_ratio.minCoeff()}}},
      {"seconds", r.seconds}};
  if (std::isfinite(r.solution.nucleus_pressure_mpa))
    j["nucleus_pressure_mpa"] = r.solution.nucleus_pressure_mpa;
  return j;
}

void write_nonlinear_fem_vtu(const std::string& path, const mesh::TetMesh& m,
                             const NonlinearFemRun& r) {
  const fem::NonlinearElementFields& f = r.fields;
  // The FE nodes list the mesh vertices first (P2: then the edge nodes).
  const Eigen::MatrixX3d vertices = r.solution.body.displacement_mm.topRows(m.num_vertices());
  mesh::write_vtu(path, m, {{"displacement", vertices}},
                  {{"cauchy_stress_MPa", f.cauchy_stress_mpa},
                   {"von_mises_MPa", f.von_mises_mpa},
                   {"pressure_MPa", f.pressure_mpa},
                   {"green_lagrange_strain", f.green_lagrange_strain},
                   {"principal_stretch", f.principal_stretch},
                   {"principal_stretch_direction_1", f.principal_stretch_directions.leftCols(3)},
                   {"principal_stretch_direction_2",
                    f.principal_stretch_directions.middleCols(3, 3)},
                   {"principal_stretch_direction_3", f.principal_stretch_directions.rightCols(3)},
                   {"fibre_stretch", f.fibre_stretch},
                   {"fibre_stress_MPa", f.fibre_stress_mpa},
                   {"volume_ratio", f.volume_ratio},
                   {"strain_energy_density_MPa", f.strain_energy_density_mpa}});
}

}  // namespace spinesim::studies
