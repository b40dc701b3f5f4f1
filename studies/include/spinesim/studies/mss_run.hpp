// Running the mass-spring disc under a rigid-plate load, static or in time (`spinesim mss`), the
// statistics of a stepped run and the model's constants as JSON (`mss`, `study probe|drive`, the
// demo).
//
// A dynamic run ramps the load linearly over the first 10 % of the steps (at least one) and then
// holds it, so the plate never jumps (a jump of the prescribed pose in one step would give the
// endplate nodes a velocity of Δx/dt). A rejected step stops the run; the result says why.
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>

namespace spinesim::output {
class VtuSeries;
}  // namespace spinesim::output

namespace spinesim::studies {

using output::VtuSeries;

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

/// The model's constants for reports: spring counts, total mass, K_d, equivalent cylinder
/// (D_u, D_l, D_m, L_m in mm; k_t in N·mm/rad per region).
nlohmann::json mss_model_json(const mss::MssModel& model, const mesh::RegionMaterials& materials);

/// The plate load of a run: a prescribed motion (pose mode) or a wrench, about `center`.
struct PlateLoad {
  bool is_wrench = false;
  mss::Vector6d value = mss::Vector6d::Zero();  ///< (t mm, theta rad) or (F N, M N·mm), global
  Eigen::Vector3d center = Eigen::Vector3d::Zero();

  /// The boundary with the load scaled by `factor` (the ramp).
  mss::Boundary boundary(double factor) const;
};

struct MssRunRequest {
  PlateLoad load;
  bool dynamic = false;  ///< false: static Newton equilibrium under the full load
  mss::DynamicsOptions dynamics;
  std::string integrator_name = "implicit";
  int steps = 0;        ///< dynamic: number of steps (>= 1)
  int frame_every = 0;  ///< dynamic: a frame every K steps (0: about 100 frames)
};

struct MssRunResult {
  MssRunRequest request;
  mss::StaticResult statics;  ///< static run: the solver's result
  StepStats stats;            ///< dynamic run
  int ramp_steps = 0;
  double time_s = 0, seconds = 0;  ///< simulated time; wall-clock of the solve or the stepping
  Eigen::VectorXd x_mm;            ///< end state
  mss::Vector6d plate_motion = mss::Vector6d::Zero();     ///< (t mm, theta rad)
  mss::Vector6d reaction_wrench = mss::Vector6d::Zero();  ///< about the moved plate centre
  double volume_mm3 = 0, rest_volume_mm3 = 0, volume_change = 0, max_displacement_mm = 0;
  Eigen::Index inverted_tets = 0;
  bool failed = false;  ///< not converged, not finite, or a rejected step
  std::string failure;  ///< one line
};

/// Solves or steps; a dynamic run adds its frames to `frames` (may be null) — the caller
/// finishes or discards them. Stage: solve or stepping (1).
MssRunResult run_mss_load(const mss::MssModel& model, const MssRunRequest& request,
                          VtuSeries* frames = nullptr, const StageHooks& hooks = StageHooks());

/// The run's fields: static (converged, iterations, residual_n) or dynamic (integrator, dt_s,
/// steps, ramp, step statistics), reaction, plate motion (deg), volume, timings.
nlohmann::json mss_run_json(const MssRunResult& r);

/// The readable summary; `constants` names the model (untuned variant or tuned file).
void print_mss_run(std::ostream& os, const mss::MssModel& model, const std::string& mesh_label,
                   const std::string& material, const std::string& constants,
                   const MssRunResult& r);

}  // namespace spinesim::studies
