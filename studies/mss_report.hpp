// Shared pieces of the mass-spring verbs (`mss`, `mss compare`, `study …`, `demo`): the result
// fields of an MSS state, the model's constants as JSON, the MSS plate stiffness, the MSS-vs-FEM
// comparison, VTU time series and atomic text files.
//
// MSS vs FEM protocol (`spinesim mss compare`, and the demo's baseline table). On one mesh,
// for each named load case (fem/load_cases.hpp, wrench w in the disc frame rotated to global):
//   (a) wrench-loaded: FEM (P1 or P2, displacement at the mesh vertices) and MSS static
//       equilibrium under the same w on the superior plate, inferior endplate fixed;
//         displacement_error = ||u_mss - u_fem||_F / ||u_fem||_F        (all vertices)
//         plate_motion_error = rms_i |r_i(q_mss) - r_i(q_fem)| / rms_i |r_i(q_fem)|,
//       r_i(q) = t + theta x (X_i - c) the rigid displacement of superior-plate node i — a
//       unit-free norm of the 6-DOF plate motion that weighs rotations by the plate's size;
//   (b) motion-loaded: the MSS plate is moved by the FEM's plate motion q_fem (exact rigid pose)
//       and its reaction wrench R_mss compared with the FEM's R_fem (= -w), with moments divided
//       by the plate's RMS radius rho (so N and N·mm/mm add up):
//         reaction_error        = |(dF, dM/rho)| / |(F_fem, M_fem/rho)|
//         reaction_force_error  = |dF| / |(F_fem, M_fem/rho)|,  reaction_moment_error = |dM/rho| / same
//       (each part relative to the FEM wrench's size; a pure-moment case has F_fem = 0, so a
//       ratio |dF|/|F_fem| would be meaningless);
//   (c) the 6x6 plate stiffness diagonal, MSS / FEM: MSS K6 by static condensation of the rest
//       Hessian onto the plate's 6 DOF (the linearisation of (b) at q = 0), FEM K6 as fem/.
// Reaction wrenches: force N and moment N·mm the disc exerts on the superior plate (the MSS's
// about the moved plate centre, the FEM's about the centre — equal to first order).
#pragma once

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace spinesim::cli {

// --- model options from the command line -----------------------------------------------------

/// The flags every MSS verb shares: which energy terms, and the ambient damping.
struct ModelFlags {
  bool no_radial = false, no_torsion = false, volume_term = false, disc_volume_term = false;
  double volume_factor = mss::MssOptions().volume_factor;
  double disc_volume_factor = mss::MssOptions().disc_volume_factor;
  double damping_n_s_per_mm = -1.0;
  CLI::Option* damping_option = nullptr;
};
/// Adds --no-radial, --no-torsion, --volume-term, --disc-volume-term, their factors and
/// --damping to `cmd`.
void add_model_flags(CLI::App* cmd, ModelFlags& flags);
/// The model options they select; throws std::invalid_argument for a negative or non-finite
/// --damping or a volume factor that is not finite and > 0.
mss::MssOptions model_options(const ModelFlags& flags);
/// "radial" (thesis) or "no-radial", "+volume-term", "+disc-volume-term", "+no-torsion": the
/// variant's name for tables.
std::string model_variant(const ModelFlags& flags);
/// "implicit", "symplectic" or "explicit"; throws std::invalid_argument naming the choices.
mss::Integrator parse_integrator(const std::string& name);

// --- stepping -------------------------------------------------------------------------------

/// One stepped run's wall-clock statistics and its first rejected step.
struct StepStats {
  int steps_done = 0, newton_iterations = 0;
  double seconds_sum = 0, seconds_max = 0;
  bool diverged = false;
  std::string message;  ///< the simulator's reason for the rejected step (one line)

  /// Steps `s` to `bc` and times it; on a rejected step records why and returns false (the
  /// state is unchanged; the caller stops).
  bool step(mss::Simulator& sim, mss::State& s, const mss::Boundary& bc);
  double mean_seconds() const { return steps_done > 0 ? seconds_sum / steps_done : 0.0; }
  /// steps_done, step_seconds_mean, step_seconds_max, newton_iterations, diverged (+ message).
  void add_to(nlohmann::json& j) const;
};

// --- results of one MSS state ------------------------------------------------------------

/// Displacement x - X at the mesh vertices, #V×3, mm (x flat 3#V, interleaved).
Eigen::MatrixX3d mss_displacement(const mss::MssModel& model, const Eigen::VectorXd& x_mm);

/// The VTU arrays of an MSS state: point data `displacement` (mm), cell data `volume_change`
/// ((V_t - V0_t)/V0_t per tetrahedron, dimensionless).
struct MssFields {
  std::vector<mesh::DataArray> point, cell;
};
MssFields mss_fields(const mss::MssModel& model, const Eigen::VectorXd& x_mm);

/// Relative volume change of the whole disc at x, (V - V0)/V0.
double volume_change(const mss::MssModel& model, const Eigen::VectorXd& x_mm);

/// The model's constants for reports: spring counts, total mass, K_d, equivalent cylinder
/// (D_u, D_l, D_m, L_m in mm; k_t in N·mm/rad per region).
nlohmann::json mss_model_json(const mss::MssModel& model, const mesh::RegionMaterials& materials);

/// MSS plate stiffness at rest about `center_mm`, by condensing the rest Hessian onto the
/// superior plate's rigid motion (t mm, theta rad): K6 = T'K_pp T - (K_fp T)' K_ff^-1 (K_fp T),
/// inferior endplate fixed; the whole-disc volume term's rank-one Hessian part is included
/// (Sherman–Morrison). Units as fem::DiscFem::stiffness_6x6. Throws std::runtime_error if K_ff
/// does not factorise.
fem::Matrix6d mss_plate_stiffness(const mss::MssModel& model, const Eigen::Vector3d& center_mm);

// --- MSS vs FEM (protocol above) --------------------------------------------------------------

struct CaseComparison {
  std::string name;
  fem::Vector6d wrench = fem::Vector6d::Zero();  ///< applied, global frame (N, N·mm)
  fem::Vector6d plate_motion_fem = fem::Vector6d::Zero(), plate_motion_mss = fem::Vector6d::Zero();  ///< (mm, rad)
  double displacement_error = 0, plate_motion_error = 0;
  fem::Vector6d reaction_fem = fem::Vector6d::Zero(), reaction_mss = fem::Vector6d::Zero();  ///< (N, N·mm)
  double reaction_error = 0, reaction_force_error = 0, reaction_moment_error = 0;
  double max_displacement_fem_mm = 0, max_displacement_mss_mm = 0;
  Eigen::Index inverted_tets = 0;  ///< inside-out tets in the MSS wrench-loaded solution
  bool converged = true;  ///< both MSS static solves converged
  int iterations = 0;     ///< Newton iterations of both MSS solves
  std::string message;    ///< why a solve did not converge
};

struct MssFemComparison {
  std::string material;
  std::string constants = "untuned Van Gelder";  ///< or "tuned (FILE)"
  double load_scale = 1.0;
  int fem_order = 2;
  Eigen::Index nodes = 0, tets = 0;
  double plate_rms_radius_mm = 0;
  std::vector<CaseComparison> cases;
  fem::Matrix6d k6_fem = fem::Matrix6d::Zero(), k6_mss = fem::Matrix6d::Zero();
  double fem_seconds = 0, mss_seconds = 0, stiffness_seconds = 0;
};

/// Runs the protocol on `fem` (already factorised, its plate centre is used) and `model` (same
/// mesh) for `cases`. A static solve that does not converge is recorded, not thrown.
/// `load_scale` multiplies every case's wrench (1: the standard loads of fem/load_cases.hpp; the
/// FEM is linear, so its relative errors do not depend on it, the nonlinear MSS's do).
MssFemComparison compare_mss_fem(const fem::DiscFem& fem, const mss::MssModel& model,
                                 const std::vector<fem::LoadCase>& cases, const std::string& material_name,
                                 const mss::StaticOptions& options = mss::StaticOptions(), double load_scale = 1.0);

nlohmann::json comparison_json(const MssFemComparison& c);
/// Readable table (markdown when `markdown`), one row per case, then the K6 diagonal ratios.
void print_comparison(std::ostream& os, const MssFemComparison& c, bool markdown);
/// One CSV row per case: errors and both reaction wrenches.
std::string comparison_csv(const MssFemComparison& c);

// --- files -----------------------------------------------------------------------------------

/// Writes `text` to `path` completely or not at all (temporary file in the same folder, then
/// rename). Throws std::runtime_error naming the file when the system refuses.
void write_text_file(const std::string& path, const std::string& text);

/// Throws std::invalid_argument unless `path`'s folder exists (checked before long runs).
void require_output_folder(const std::string& path, const std::string& option);

/// A VTU time series of MSS states: frames `<stem>/<stem>_NNNNNN.vtu` next to `<stem>.pvd`
/// (the PVD lists them relative to its folder). Frames are written as they come (atomically);
/// finish() writes the PVD; discard() removes every frame written (for a failed run).
class VtuSeries {
 public:
  /// `pvd_path` ends in .pvd; its folder must exist; the frame folder is created.
  explicit VtuSeries(const std::string& pvd_path);
  void add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm);
  void finish();
  void discard();
  const std::string& pvd_path() const { return pvd_path_; }
  std::size_t num_frames() const { return entries_.size(); }
  /// Absolute or caller-relative paths of the frames written.
  std::vector<std::string> frame_paths() const;

 private:
  std::string pvd_path_, folder_, stem_;
  std::vector<mesh::PvdEntry> entries_;
};

}  // namespace spinesim::cli
