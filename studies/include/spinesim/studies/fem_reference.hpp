// The FEM reference of a disc mesh as a study driver (`spinesim fem`, the demo): a rigid superior
// plate moved or loaded, the inferior endplate fixed; and the unit conversions and readable output
// of its plate results. The command line speaks degrees; the solver speaks radians.
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/fem/plate_stiffness.hpp"
#include "spinesim/fem/stress_fields.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace spinesim::studies {

// The degree units of the program's plate motions and stiffnesses (fem/plate_stiffness.hpp).
using fem::motion_deg_to_rad;
using fem::motion_rad_to_deg;
using fem::stiffness_per_degree;

inline constexpr const char* kStiffnessUnits =
    "rows Fx,Fy,Fz [N], Mx,My,Mz [N·mm]; columns tx,ty,tz [mm], rx,ry,rz [deg]";

void print_stiffness(std::ostream& os, const fem::Matrix6d& k_rad);

/// One load on the superior plate: a prescribed motion, a wrench, or a named load case (whose
/// disc-frame wrench is rotated into the mesh's frame). At most one is set; none = zero motion.
struct FemRunRequest {
  int order = 2;
  fem::Formulation formulation = fem::Formulation::displacement;
  std::optional<Eigen::Vector3d> center;  ///< plate centre, mm; default: DiscFem's
  std::optional<fem::Vector6d> motion;    ///< (t mm, theta rad), global
  std::optional<fem::Vector6d> wrench;    ///< (F N, M N·mm), global
  const fem::LoadCase* load_case = nullptr;
};

struct FemRunResult {
  FemRunRequest request;
  std::string material;
  Eigen::Index nodes = 0, tets = 0, fem_nodes = 0, dofs = 0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  fem::Vector6d applied_wrench = fem::Vector6d::Zero();  ///< of a wrench or case load
  fem::PlateSolution solution;
  fem::Matrix6d stiffness = fem::Matrix6d::Zero();  ///< rows (F, M), columns (t mm, theta rad)
  fem::Timings timings;
  double load_solve_s = 0;
  fem::ElementFibres fibres;  ///< the annulus fibre field (empty without fibres)
  fem::ElementFields fields;  ///< per-tet stress, strain and energy (stress_fields.hpp)
  double strain_energy_mj = 0;  ///< sum over tets of energy density × volume (N·mm = mJ)
};

/// Assembles, factorises and solves the one load. Stages: assembly, solve (2). Throws
/// std::invalid_argument when more than one load is given.
FemRunResult run_fem_reference(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                               const FemRunRequest& request,
                               const StageHooks& hooks = StageHooks());

/// mesh, nodes, tets, order, DOF, material, plate centre, motion (deg), reaction, 6x6 stiffness
/// (per degree), max |u|, timings, case; with units.
nlohmann::json fem_run_json(const FemRunResult& r, const std::string& mesh_label);

/// What `export --format abaqus` wrote: the deck's element type, load and counts.
struct DeckExport {
  std::string element;  ///< C3D4 or C3D10
  std::string load;     ///< "motion" or "wrench"
  fem::Vector6d value = fem::Vector6d::Zero();  ///< (t mm, theta rad) or (F N, M N·mm), global
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
};

/// Writes the problem `request` describes (order, load or case, centre; no load: zero motion)
/// as an Abaqus/CalculiX deck at `path` (fem/abaqus_deck.hpp), atomically. Throws
/// std::invalid_argument for the mixed formulation (CalculiX has no Taylor–Hood element) or
/// more than one load.
DeckExport export_abaqus_deck(const std::string& path, const mesh::TetMesh& m,
                              const mesh::RegionMaterials& materials, const FemRunRequest& request,
                              const std::string& title);

/// What `export --format febio` wrote: the element type and the plate motion it prescribes.
struct FebioExport {
  std::string element;                           ///< tet4 or tet10
  fem::Vector6d motion = fem::Vector6d::Zero();  ///< (t mm, theta rad), global
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  bool solved = false;  ///< the motion is this FEM's answer to `from_wrench` (a wrench or case)
  fem::Vector6d from_wrench = fem::Vector6d::Zero();  ///< (F N, M N·mm), global
};

/// Writes the problem `request` describes as an FEBio file at `path` (fem/febio_deck.hpp),
/// atomically. FEBio prescribes plate motions only (a wrench needs a rigid part): a wrench or a
/// named case is written as the plate motion run_fem_reference finds under it. Throws
/// std::invalid_argument for the mixed formulation or more than one load.
FebioExport export_febio_deck(const std::string& path, const mesh::TetMesh& m,
                              const mesh::RegionMaterials& materials, const FemRunRequest& request,
                              const std::string& title);

/// The readable summary: plate centre, motion, reaction and the 6x6 stiffness.
void print_fem_run(std::ostream& os, const FemRunResult& r, const std::string& mesh_label);

/// The run's point and cell arrays, named as write_fem_vtu writes them (units in the names).
struct FemArrays {
  std::vector<mesh::DataArray> points, cells;
};
FemArrays fem_run_arrays(const mesh::TetMesh& m, const FemRunResult& r);

/// Writes the run to a VTU: point data `displacement` (mm) and, from the mixed formulation,
/// `pressure` (MPa, hydrostatic); cell data of the fibre field when there is one:
/// `fibre_direction_1`, `fibre_direction_2` (unit; zero without fibres), `fibre_angle_deg` (to the
/// transverse plane; 0 without fibres), `annulus_depth` (0 at the nucleus, 1 at the outer wall;
/// -1 outside the annulus).
void write_fem_vtu(const std::string& path, const mesh::TetMesh& m, const FemRunResult& r);

/// "displacement" or "mixed" (command-line names).
fem::Formulation parse_formulation(const std::string& name);
const char* formulation_name(fem::Formulation f);

}  // namespace spinesim::studies
