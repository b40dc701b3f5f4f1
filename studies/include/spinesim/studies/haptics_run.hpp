// The haptic loop as a study driver: build the rigid scene (the spine's 18 bodies, one vertebra
// or a plane), open a device, run the 1 kHz servo loop with a renderer and the safety chain,
// record the run, and report the loop's own statistics. The command line (`spinesim haptics
// run`) and the viewer call this.
#pragma once

#include "spinesim/haptics/device.hpp"
#include "spinesim/haptics/latency_probe.hpp"
#include "spinesim/haptics/scene.hpp"
#include "spinesim/haptics/scene_builder.hpp"
#include "spinesim/haptics/servo.hpp"
#include "spinesim/spine/seating.hpp"
#include "spinesim/studies/disc_palpation_setup.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace spinesim::mss {
class MssModel;
}

namespace spinesim::studies {

// The rigid scene is built by the haptics library (haptics/scene_builder.hpp).
using haptics::build_haptic_scene;
using haptics::check_scene_name;
using haptics::HapticScene;
using haptics::HapticSceneRequest;
using haptics::Registration;
using haptics::registration_json;

/// What a viewer gets once a session is set up (on the session's thread, before the loop
/// starts; the references are valid only during the call: copy what is needed).
struct HapticsLiveSetup {
  const HapticScene& scene;
  const mss::MssModel* disc = nullptr;  ///< the palpated disc (scene "disc"), else null
  std::string disc_level;
  haptics::DeviceCapabilities capabilities;
  double stiffness_n_per_mm = 0, probe_radius_mm = 0;
  std::string device, spine;  ///< the device's name; the compliant stage ("": none)
  Eigen::Vector3d device_start_mm = Eigen::Vector3d::Zero();  ///< mouse: where the probe starts
  std::string disc_model;  ///< what is palpated: "mass-spring" or "linear FEM" ("": no disc)
};

/// What a viewer gets about every 10 ms while the loop runs (from the slow side).
struct HapticsLiveFrame {
  haptics::ServoStatus status;
  double loop_time_s = 0;     ///< the loop's clock
  Eigen::VectorXd disc_x_mm;  ///< the disc's node positions (empty without a disc)
};

/// A viewer's hooks into a session: the mouse device's input (needed for --device mouse), the
/// set-up and the frames. Both callbacks run on the session's thread and must be quick.
struct HapticsLiveHooks {
  haptics::TripleBuffer<haptics::PointerInput>* pointer = nullptr;
  std::function<void(const HapticsLiveSetup&)> ready;
  std::function<void(const HapticsLiveFrame&)> frame;
};

struct HapticsRunRequest {
  HapticSceneRequest scene;
  std::string device = "sim";  ///< sim, replay, null, openhaptics, dhd; mouse (with live hooks)
  std::string sdk_library;     ///< openhaptics/dhd: the vendor's shared library (default name)
  /// openhaptics/dhd: where the device's origin lands in the scene (mm; NaN: the scene's centre)
  /// and from where the user looks: "back" (behind the patient: device x → −x, z → −z) or
  /// "front" (device axes = scene axes).
  Eigen::Vector3d workspace_center_mm = Eigen::Vector3d::Constant(std::nan(""));
  std::string view = "back";
  std::string model = "touch";  ///< capability record (haptics::device_models)
  std::string script;           ///< sim: the hand's set-point trajectory (default per scene)
  std::string replay;           ///< replay: a recorded run
  double duration_s = 0;        ///< 0: the script's or recording's length (null: 10 s)
  double probe_radius_mm = 4;
  std::string renderer = "proxy";  ///< proxy or gao-gibson
  double stiffness_n_per_mm = 0;   ///< 0: the device's usable stiffness within Colgate–Brown
  std::string record;  ///< CSV of every tick, synced to disk block by block as the loop runs
  /// The compliant stage (scene "spine" only): "" (off), "multirate" or "database".
  std::string spine;
  std::string database;  ///< the database file ("": data/spine/displacement_db.json)
  double coupling_stiffness_n_per_mm = 0;  ///< felt hook spring (0: the rendering stiffness)
  double coupling_damping_n_s_per_mm = 0;  ///< felt, relative to the hook
  /// 6-DOF devices with torque (--spine multirate): the hook's torsional spring, felt (N·mm/rad;
  /// NaN: the device's usable rotational stiffness; 0: the hook holds no orientation).
  double rotational_stiffness_nmm_per_rad = std::nan("");
  /// Spine or disc N per felt N (0: the spine's 600 N, or 100 N on the disc, at the device's
  /// peak force).
  double force_scale = 0;
  bool spine_recruit = true;  ///< muscles recruited in the spine solves (as the database)
  /// The spine's posture for --spine multirate: "standing" or "seated" (in `chair`, solved by
  /// spine::solve_seated; the hook pushes on the seated spine leaning on the backrest).
  std::string posture = "standing";
  spine::Chair chair;
  /// Disc palpation (scene "disc"): the tuned parameters (palpation_params_path) and the
  /// budget the disc's step must fit (us); the coupling is coupling_stiffness/damping.
  std::string disc_params;
  /// "multirate": the disc stepped every disc_period_ms on its thread, its local contact model
  /// felt every tick (haptics/disc_palpation.hpp); "direct": the disc stepped every tick.
  std::string disc_solver = "multirate";
  /// "mss": the tuned mass-spring disc; "fem": the linear FEM disc it was tuned to (static).
  std::string disc_model = "mss";
  double disc_period_ms = 10;  ///< multirate: the disc's step, 1-10 ms
  double disc_budget_us = 0;   ///< 0: 500 us (direct) or 80 % of the period (multirate)
  /// After the run, the hand's recorded path through a synchronous solve (the disc stepped every
  /// 1 ms off the clock) and the felt force's error against it (multirate only).
  bool disc_sync_check = false;
  double disc_cell_size_mm = 0;  ///< > 0: this resolution, not the budget check's choice
  std::string write_scene;       ///< folder: each body's surface as <name>.obj (world, mm)
  bool realtime_priority = true;
  bool measure_floor = true;                ///< run the latency probe beside the servo
  double spin_us = 400;                     ///< spin this long before each deadline (0: sleep only)
  const std::atomic<bool>* stop = nullptr;  ///< set by the front end (Ctrl-C) to end the run
  const HapticsLiveHooks* live = nullptr;   ///< a viewer's hooks (null: none)
};

/// The hostile trajectory a --script of the form "hostile:NAME" names (haptics/hostile.hpp), or ""
/// for any other script; throws std::invalid_argument (one line) for an unknown NAME.
std::string hostile_script_name(const std::string& script);
/// The shipped scripts (data/haptics/), and the default one for a scene.
std::string default_haptic_script(const std::string& scene, const std::string& data_dir);

struct HapticsRunResult {
  HapticsRunRequest request;
  std::string scene_description;
  int bodies = 0, triangles = 0;
  bool registered = false;
  Registration registration;  ///< of the real vertebrae, when used
  double scene_seconds = 0;
  int scene_cached_bodies = 0;  ///< generated bodies read from the vertebra cache
  double startup_seconds = 0;   ///< from the call to the first tick (scene, disc, stage, device)
  haptics::DeviceCapabilities capabilities;
  double stiffness_n_per_mm = 0, passive_limit_n_per_mm = 0;
  haptics::ServoStats stats;
  /// The machine's floor in the same run: a bare periodic thread beside the servo
  /// (haptics/latency_probe.hpp; wakeups = 0 when it was not run).
  haptics::LatencyProbeStats floor;
  std::int64_t recorded_rows = 0;
  // The compliant stage (spine empty: off).
  std::string spine;
  double coupling_stiffness_n_per_mm = 0, force_scale = 0, spine_max_force_n = 0;
  double coupling_damping_n_s_per_mm = 0;  ///< the disc coupling's, as used
  double rotational_stiffness_nmm_per_rad = 0;  ///< 0: the hook holds no orientation
  double rotational_passive_limit_nmm_per_rad = 0;
  std::string twist_note;  ///< why the hook holds no orientation, when it does not
  std::int64_t worker_solves = 0, worker_failures = 0;
  double worker_update_ms = 0, worker_rate_hz = 0;  ///< per update (solve + sensitivity)
  std::string worker_error;
  // Disc palpation (disc_level empty: off).
  std::string disc_level, disc_tuned_file, disc_note, disc_thread;
  long disc_tets = 0;
  double disc_cell_size_mm = 0;
  std::vector<DiscCandidate> disc_candidates;  ///< the budget check, finest first
  std::int64_t disc_steps = 0, disc_overruns = 0, disc_failed_steps = 0;
  std::int64_t disc_dropped_periods = 0;  ///< worker periods given up (more than one behind)
  haptics::Percentiles disc_step_us;
  double disc_max_force_n = 0, disc_volume_change_min = 0, disc_volume_change_max = 0;
  double disc_max_indentation_mm = 0, disc_rate_hz = 0;
  std::int64_t disc_stale_ticks = 0;  ///< multirate: ticks whose local model was stale
  /// --disc-sync-check: the felt force's error against the synchronous solve (disc N).
  std::int64_t sync_ticks = 0;
  double sync_seconds = 0;
  haptics::ForceError sync_error;
};

/// Refuses what cannot run (flags, device backend, output folders), before any work: throws
/// std::invalid_argument (one line), std::runtime_error for a vendor library that is missing.
void check_haptics_request(const HapticsRunRequest& request);

/// Validates everything (device, model, files, radius, output folder) before any work, builds
/// the scene, runs the loop. `status(status)` about every 100 ms for a live line (may be empty);
/// `scene_progress` as for build_haptic_scene. Throws std::invalid_argument (one line) for bad
/// input, std::runtime_error for a device that cannot be opened; nothing is written then.
HapticsRunResult run_haptics(const HapticsRunRequest& request, const std::string& data_dir,
                             const std::function<void(const haptics::ServoStatus&)>& status = {},
                             const std::function<void(int, int)>& scene_progress = {});

nlohmann::json haptics_run_json(const HapticsRunResult& r);
std::string haptics_run_table(const HapticsRunResult& r);

/// `spinesim haptics devices`: the backends built in, what each found on this machine (the
/// vendor libraries `openhaptics_lib`/`dhd_lib`, default names when empty) and the models known.
nlohmann::json haptic_devices_json(const std::string& openhaptics_lib = "",
                                   const std::string& dhd_lib = "");
std::string haptic_devices_table(const std::string& openhaptics_lib = "",
                                 const std::string& dhd_lib = "");

/// The deadlines a run missed, judged: empty when at most `max_missed_percent` % of its ticks
/// missed theirs, else one line saying how many, of how many, against what limit. A shared
/// machine misses some (compare `cyclictest` in the same minute, docs/benchmarks.md).
std::string missed_deadlines_warning(const HapticsRunResult& r, double max_missed_percent);

}  // namespace spinesim::studies
