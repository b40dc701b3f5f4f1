// The disc scene of the haptic loop (`haptics run --scene disc --level L4-L5`): the level's tuned
// mass-spring disc between its two vertebrae, meshed at the finest resolution whose step fits the
// budget on this machine. At start, for each candidate cell size (finest first) the disc is meshed
// (CGAL, as `mesh disc --level`, or read from the disc cache), built with its tuned parameters,
// and stepped with the probe pressed 2 mm into its anterior wall (up to 300 steps, at most about
// half a second of them); the first whose fourth-worst step (CPU time) fits the budget is used.
// What could not be held (no candidate of >= min_tets fits) is said in `note`.
//
// The disc stepped is the tuned mass-spring disc (`disc_model` "mss") or, with "fem", the linear
// FEM disc it was tuned to (fem/contact_disc.hpp: the tuned set's material on the same mesh, both
// endplates held, static under the probe) — the reference itself palpated at its resolution.
#pragma once

#include "spinesim/haptics/disc_palpation.hpp"
#include "spinesim/haptics/palpable_disc.hpp"
#include "spinesim/haptics/servo.hpp"
#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace spinesim::studies {

/// The palpated disc's parameters: "" or "fibre-reinforced" name the shipped fibre-network set
/// (data/tuned_fibre_discs.json: the nonlinear fibre-reinforced disc), "real-disc" the shipped
/// linear set (data/tuned_discs.json: the isotropic real-disc); anything else is a file's path,
/// which must exist (std::invalid_argument naming the shipped sets otherwise).
std::string palpation_params_path(const std::string& params, const std::string& data_dir);

struct DiscSceneRequest {
  std::string level = "L4-L5";
  std::string params;      ///< tuned set or tuned.json, or a shipped set's name (below)
  double budget_us = 500;  ///< the disc step's p99 must fit this (half the 1 ms tick)
  std::vector<double> cell_sizes_mm = {2.0, 2.5, 3.0, 4.0};  ///< finest first
  int min_tets = 5000;  ///< below this the note says the target resolution was not held
  /// > 0: use this cell size whatever its step costs (measured and reported, not chosen by).
  double fixed_cell_size_mm = 0;
  /// Where meshed candidates are kept between runs (mesh/disc_cache.hpp); "": mesh every time.
  std::string cache_dir;
  std::string disc_model = "mss";  ///< "mss": the tuned mass-spring disc; "fem": its linear FEM
  haptics::DiscPalpationOptions palpation;
};

struct DiscCandidate {
  double cell_size_mm = 0;
  long tets = 0;
  haptics::Percentiles step_us;      ///< wall time of a step: the solver and the host's stalls
  haptics::Percentiles step_cpu_us;  ///< the step thread's CPU time: the solver's own cost
  /// The fourth-worst step's CPU time: the p99 of 300 steps; of the fewer a slow disc gets in
  /// half a second, still the solver's cost and not a host's three stalls.
  double judged_cpu_us = 0;
  bool fits = false;  ///< judged_cpu_us within the budget
};

struct DiscSetup {
  /// The tuned mass-spring disc on the chosen mesh (owns the mesh; with the FEM disc it is what
  /// the viewer colours the disc's mesh by).
  std::unique_ptr<mss::MssModel> model;
  /// Makes the palpated disc afresh (the synchronous check's reference runs on its own copy).
  std::function<std::unique_ptr<haptics::PalpableDisc>()> make_disc;
  std::unique_ptr<haptics::DiscPalpation> palpation;
  mss::Boundary plates;  ///< the endplates, held
  std::vector<DiscCandidate> tried;
  DiscCandidate chosen;
  std::string tuned_file, note;
};

/// Throws std::invalid_argument (one line) for an unknown level, a level without tuned
/// parameters, bad palpation options, or when no candidate fits the budget (naming the fastest).
DiscSetup make_disc_setup(const DiscSceneRequest& request, const std::string& data_dir,
                          const std::function<void(const std::string&)>& stage = {});

/// The linear FEM disc of `mesh` and `materials` under a probe of `radius_mm` (penalty 0: the
/// FEM's default, fem::ContactDisc::default_penalty) behind the palpation interface.
std::unique_ptr<haptics::PalpableDisc> make_fem_palpable_disc(const mesh::TetMesh& mesh,
                                                              const mesh::RegionMaterials& materials,
                                                              double radius_mm,
                                                              double penalty_n_per_mm);

/// The disc's anterior wall point at mid-height and its outward normal (spine frame): where the
/// budget check presses, and where the shipped script presses.
std::pair<Eigen::Vector3d, Eigen::Vector3d> disc_anterior_wall(const mesh::TetMesh& disc);

}  // namespace spinesim::studies
