// What the stepped MSS studies (probe, drive) share: their options, the loop's bookkeeping — the
// simulator from rest, a VTU time series and a CSV per run in the output folder, the step
// statistics — and small summaries.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>
#include <string>

namespace spinesim::studies {

/// How a stepped study runs: integrator, step, frames, model terms and where files go.
struct SteppedStudyOptions {
  std::string out = "study-out";  ///< output folder (created)
  mss::DynamicsOptions dynamics;  ///< integrator, dt_s, Newton iterations, matrix update
  std::string integrator_name = "implicit";
  int frame_every = 10;                  ///< a VTU frame every K steps
  mss::MssOptions model;                 ///< MSS terms
  std::string model_variant = "radial";  ///< its name for reports
};

/// Throws std::invalid_argument for a step that is not finite and > 0 or frame_every < 1.
void check(const SteppedStudyOptions& options);

/// Min and max of a signed quantity, and the value of largest magnitude.
struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v) { lo = std::min(lo, v), hi = std::max(hi, v); }
  double extreme() const { return std::abs(lo) > std::abs(hi) ? lo : hi; }
  /// extreme(), or 0 when nothing was added.
  double extreme_or_zero() const { return std::isfinite(lo) ? extreme() : 0.0; }
};

/// One run of a stepped study: `steps` steps of the simulator from rest, a frame of
/// <out>/<stem>.pvd every frame_every steps (and at the last), rows of <out>/<stem>.csv written
/// by the caller after each step. The output folder must exist.
class SteppedRun {
 public:
  SteppedRun(const mss::MssModel& model, const SteppedStudyOptions& options,
             const std::string& stem, const std::string& csv_header, int steps);
  /// Step k (1-based) to `bc`; false on a rejected step (the state is unchanged: stop).
  bool step(int k, const mss::Boundary& bc);
  const mss::State& state() const { return state_; }
  std::ostream& csv() { return csv_; }
  const StepStats& stats() const { return stats_; }
  int steps() const { return steps_; }
  /// Writes the series and the CSV (the finite states up to a rejected step).
  void finish();
  const std::string& pvd_path() const { return frames_.pvd_path(); }
  const std::string& csv_path() const { return csv_path_; }
  std::size_t num_frames() const { return frames_.num_frames(); }

 private:
  const mss::MssModel& model_;
  int frame_every_, steps_;
  mss::Simulator sim_;
  mss::State state_;
  VtuSeries frames_;
  std::ostringstream csv_;
  std::string csv_path_;
  StepStats stats_;
};

/// {source, nodes, tets, volume_mm3} of a study's mesh.
nlohmann::json study_mesh_json(const mesh::TetMesh& m);

/// A file-name-safe version of a name (material, level): [A-Za-z0-9_-], others become '_'.
std::string file_stem(const std::string& name);

}  // namespace spinesim::studies
