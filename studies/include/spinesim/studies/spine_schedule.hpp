// Loads that vary in time (`spinesim spine schedule`; spine/README.md, "Loads in time"): forces
// and couples on any vertebra given as a CSV schedule, solved as a quasi-static sequence.
//
// The schedule: a header `time_s,VERTEBRA.COMPONENT,…` with COMPONENT one of fx_n, fy_n, fz_n
// (N, at the vertebra's F.1 centre) and mx_nmm, my_nmm, mz_nmm (a couple, N·mm), then one row
// per key time, strictly increasing; between key times every load is linear in time. Example:
//
//   time_s,T7.fz_n,L1.mx_nmm
//   0,0,0
//   2,300,0
//   4,300,5000
//
// Quasi-static: the spine model is elastic and keeps no history (recruitment and equilibrium
// depend on the loads of the moment only), so each sampled time is its own equilibrium and the
// sequence's answer does not depend on how finely it is sampled. With --dynamic the motion is
// integrated as well (run_schedule_dynamics). Whether inertia matters is measured: the spine's first natural frequency f1 at the first step (spine/dynamics.hpp) beside
// the schedule's fastest ramp T_r bounds the motion's overshoot of the quasi-static answer by
// min(1, 1/(π f1 T_r)) of a ramp's step; above kInertiaMatters the output says inertia may matter.
#pragma once

#include "spinesim/spine/dynamics.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace spinesim::studies {

struct LoadSchedule {
  std::string path;
  std::vector<std::string> columns;  ///< "T7.fz_n", … (the header after time_s)
  /// Per column: the vertebra index and the component (0–2 force x, y, z; 3–5 couple x, y, z).
  std::vector<std::pair<int, int>> targets;
  std::vector<double> time_s;        ///< key times, strictly increasing
  /// Per key time, per column: the value (N or N·mm).
  std::vector<std::vector<double>> values;
};

/// Reads a schedule. Throws std::invalid_argument (one line naming the file, and the row and
/// column where there is one) for: no time_s first column, an unknown vertebra or component, a
/// column given twice, an empty cell (a gap), a value that is not a finite number, a time that
/// does not increase, no rows, or a force or couple beyond what a spine solve accepts.
LoadSchedule read_load_schedule(const std::string& path);

/// The loads at time t (linear between key times; t outside [first, last] is refused).
std::vector<spine::ExternalLoad> schedule_loads(const LoadSchedule& s, double t);

/// The sampled times: every key time, and with step_s > 0 every multiple of step_s from the first
/// key time on as well (sorted, duplicates removed).
std::vector<double> schedule_times(const LoadSchedule& s, double step_s);

/// A ramp whose undamped overshoot bound exceeds this share of its step: inertia matters.
inline constexpr double kInertiaMatters = 0.05;

struct ScheduleStep {
  double t_s = 0;
  std::vector<spine::ExternalLoad> loads;
  spine::SpineSolution solution;
  std::string error;  ///< empty: converged
};

/// The motion at one sampled time (run_schedule_dynamics): T1's displacement and the lumbar
/// joints' axial forces with the d'Alembert loads of the motion.
struct DynamicSample {
  double t_s = 0;
  Eigen::Matrix<double, 6, 1> t1_displacement = Eigen::Matrix<double, 6, 1>::Zero();
  double l4l5_axial_n = 0, l5s1_axial_n = 0;
};

struct ScheduleRun {
  LoadSchedule schedule;
  spine::SpineModel model;
  std::vector<ScheduleStep> steps;
  int failed = 0;  ///< steps whose equilibrium was not found (kept, with their error)
  /// Inertia (see the header): f1 (Hz) at the first converged step, the shortest interval
  /// between key times over which a load changes (s), and the overshoot bound (a fraction);
  /// NaN / infinity when unknown or the loads never change.
  double first_frequency_hz = NAN, fastest_ramp_s = INFINITY, overshoot_bound = 0;
  /// The motion (run_schedule_dynamics; empty when not run), its time step and damping ratio.
  std::vector<DynamicSample> dynamic;
  double dynamic_dt_s = 0, damping_ratio = 0;
  int dynamic_steps = 0;
  double dynamic_seconds = 0;
  double seconds = 0;
};

/// Solves every sampled time on `workers` threads (0: one per core); `progress(done, total)` in
/// the calling thread. A step that does not reach equilibrium is kept with its error; the
/// others go on.
ScheduleRun run_load_schedule(const std::string& data_dir, const LoadSchedule& schedule,
                              const spine::ModelOptions& model, const spine::SolveOptions& solve,
                              double step_s, int workers,
                              const std::function<void(int, int)>& progress = {});

/// Integrates the motion through the schedule (spine/dynamics.hpp): from the first step's
/// equilibrium at rest, the loads as scheduled and the muscle forces held as the quasi-static
/// steps recruited them (linear in time between steps); fills run.dynamic at every sampled time.
/// Throws std::invalid_argument when a step reached no equilibrium or for bad options,
/// spine::SolveError when a time step does not converge.
void run_schedule_dynamics(ScheduleRun& run, const spine::DynamicsOptions& options);

/// One row per step: time, converged, the loads, each joint's compression and shear (joint
/// frame) and each vertebra's displacement (mm, deg). A failed step's numbers are empty cells.
std::string schedule_csv(const ScheduleRun& run);
nlohmann::json schedule_json(const ScheduleRun& run);
void print_schedule(std::ostream& os, const ScheduleRun& run);

/// Writes the vertebrae's motions as a spine recording (the `haptics run --record` format, no
/// hook), which `spinesim spine discs --record` drives the offline discs with: one row a
/// millisecond, as a servo writes it, each vertebra moving linearly (and along the geodesic
/// rotation) between the converged steps; failed steps are left out. Throws
/// std::invalid_argument when fewer than two steps converged.
void write_schedule_recording(const ScheduleRun& run, const std::string& path);

}  // namespace spinesim::studies
