// Running the mass-spring disc for a report: the statistics of a stepped run and the model's
// constants as JSON (`spinesim mss`, `study probe|drive`, the demo).
#pragma once

#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::studies {

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

}  // namespace spinesim::studies
