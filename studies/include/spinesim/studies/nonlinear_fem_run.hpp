// `spinesim fem --nonlinear`: the nonlinear disc (fem/nonlinear_disc.hpp: finite strain,
// tension-only exponential fibres, a nearly incompressible nucleus) under the same one plate load
// as the linear `fem`, with its per-tet fields (fem/nonlinear_fields.hpp) for a VTU.
#pragma once

#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/fem/nonlinear_fields.hpp"
#include "spinesim/studies/fem_reference.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::studies {

struct NonlinearFemRun {
  fem::NonlinearPlateSolution solution;
  fem::NonlinearElementFields fields;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double fibre_k2 = 0;
  Eigen::Index dofs = 0;
  int order = 1;
  int load_increments = 10;
  std::string volumetric_form;
  double seconds = 0;
};

/// Solves the load `request` describes (a motion, a wrench or a named case; none: zero motion)
/// in `load_increments` steps. Throws std::invalid_argument for the mixed formulation (the
/// nonlinear disc has its own volumetric forms), more than one load or bad increments, and
/// std::runtime_error when Newton does not converge. Stage: solve (1).
NonlinearFemRun run_nonlinear_fem(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                                  const FemRunRequest& request, int load_increments,
                                  const StageHooks& hooks = StageHooks());

/// Plate motion (deg), reaction, nucleus pressure, Newton counts, the fields' extremes, timings.
nlohmann::json nonlinear_fem_json(const NonlinearFemRun& r, const std::string& mesh_label,
                                  const std::string& material);

/// Point data `displacement` (mm); cell data cauchy_stress_MPa (xx yy zz xy yz xz),
/// von_mises_MPa, pressure_MPa, green_lagrange_strain, principal_stretch,
/// principal_stretch_direction_1..3, fibre_stretch,
/// fibre_stress_MPa, volume_ratio, strain_energy_density_MPa.
void write_nonlinear_fem_vtu(const std::string& path, const mesh::TetMesh& m,
                             const NonlinearFemRun& r);

}  // namespace spinesim::studies
