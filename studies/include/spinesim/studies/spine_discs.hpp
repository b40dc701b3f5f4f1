// The hybrid spine offline (thesis 5.4, 6.4): the 17 tuned mass-spring discs T1-T2 … L5-S1
// simulated between the vertebra poses of a compliant-stage recording. Each disc is the level's
// structured disc (mesh/structured_disc.hpp) in the spine frame; its inferior endplate (label 1)
// moves rigidly with the lower vertebra, its superior endplate (label 2) with the upper one (the
// sacrum stays put); implicit Euler, one step per recorded tick (1 ms), all discs stepped together
// (mss::DiscSet). The run starts from each disc's static equilibrium at the first recorded
// posture, so the gravity posture the recording starts in is not a jolt.
//
// Each disc must have been calibrated on the very mesh simulated (its tuned entry's mesh
// fingerprint): the coarse structured discs do not inherit the fine CGAL meshes' scales well
// (docs/benchmarks.md, "The hybrid spine offline"), so data/tuned_structured_discs.json holds
// their own (`spinesim calibrate --level all --structured`). A set records the structured
// resolution it was fitted on, and the discs are meshed at it: the fibre networks of the
// nonlinear disc (data/tuned_structured_fibre_discs.json) need finer discs than the linear set.
//
// Written to the output folder:
//   spine.pvd + spine/  ParaView time series, two parts per frame: part 0 all 17 discs in one
//                       VTU (point `displacement` mm; cell `volume_change`, `spring_strain` (the
//                       largest-magnitude edge strain of the tet), `disc` (0 = T1-T2 …), `region`),
//                       part 1 the 18 vertebra surfaces at their poses (cell `body`, 0 = T1 … 17 =
//                       S1) — omitted with vertebra_triangles = 0; zlib-compressed VTU frames;
//   discs.csv           the per-disc table (peaks over the run);
//   disc_motion.csv     per frame and disc: the upper plate's motion relative to the lower
//                       vertebra in the disc's axes (x lateral, y axial, z anterior; mm and deg),
//                       volume change, inverted tets, reaction force and moment;
//   discs.json          all of it with the run's timings.
#pragma once

#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/haptics/recording.hpp"
#include "spinesim/mesh/structured_disc.hpp"
#include "spinesim/mss/disc_set.hpp"
#include "spinesim/spine/model.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace spinesim::studies {

// The recording format is the haptic loop's (haptics/recording.hpp).
using haptics::DragFrame;
using haptics::DragRecording;
using haptics::read_drag_recording;

/// The 17 discs of the spine, each its level's structured disc with its tuned parameters.
struct SpineDiscs {
  std::vector<std::string> levels;  ///< "T1-T2" … "L5-S1"
  std::vector<mss::MssModel> models;
  /// Per disc: index of the upper and lower vertebra in the spine model (T1 = 0 … L5 = 16); the
  /// lower of L5-S1 is -1 (the sacrum, fixed).
  std::vector<int> upper, lower;
  std::string resolution;  ///< the structured discs' "S sectors x R rings x L layers"
};

/// What `spine discs --params` names: "" or "real-disc" the shipped linear set
/// (data/tuned_structured_discs.json), "fibre-reinforced" the shipped fibre networks of the
/// nonlinear disc (data/tuned_structured_fibre_discs.json); anything else is a file's path, which
/// must exist (std::invalid_argument naming the shipped sets otherwise).
std::string spine_discs_params_path(const std::string& params, const std::string& data_dir);

/// Builds the discs, each meshed at the structured resolution the set was calibrated on
/// (calibration::structured_resolution), scaled to the model's body and, for a scoliotic model,
/// carried wedged between its vertebrae's rest poses (mesh::carry_between). Throws std::invalid_argument (one line) for a level
/// missing from `tuned`, or an entry fitted on another mesh than this level's structured disc
/// (naming both meshes and how to calibrate the structured ones), or another material than the
/// set's.
SpineDiscs build_spine_discs(const spine::SpineModel& model, const calibration::TunedSet& tuned);

struct SpineDiscsRequest {
  std::string recording;  ///< a compliant-stage recording (haptic_recording.hpp)
  std::string
      tuned;  ///< tuned set's path or a shipped name (spine_discs_params_path); empty: real-disc
  std::string out;               ///< output folder (created if missing; its parent must exist)
  double frame_period_s = 0.05;  ///< a .pvd frame (and disc_motion.csv rows) this often
  int vertebra_triangles = 500;  ///< per vertebra surface in the series; 0: no vertebrae
  int threads = 0;               ///< discs stepped in parallel; 0: one per core
  int newton_iterations = 1;     ///< per implicit step
  /// false: the rest factorisation is kept (frozen; the nonlinear forces are exact, the matrix
  /// the rest stiffness); true: refactorised every Newton iteration (~50x slower).
  bool refactorize = false;
};

/// The per-disc table: peaks over the run (the first frame's equilibrium included).
struct DiscPeaks {
  std::string level;
  double compression_mm = 0;  ///< largest shortening of the disc axis (>= 0)
  double shear_mm = 0;        ///< largest in-plane displacement of the upper plate centre
  double rotation_deg = 0;    ///< largest relative rotation angle
  double volume_change_min = 0, volume_change_max = 0;  ///< (V - V0)/V0
  long inverted_tets = 0;                               ///< most at any step
  double force_n = 0, moment_nmm = 0;  ///< largest reaction on the upper plate (about its centre)
  int rejected_steps = 0;
};

struct SpineDiscsResult {
  SpineDiscsRequest request;
  std::string fingerprint;  ///< the spine model's
  spine::Subject subject;   ///< the recorded spine's body (resolved)
  spine::ScoliosisCurve scoliosis;  ///< its curve (cobb_deg 0: straight); the discs rest in it
  bool recording_complete = false;
  std::string recording_incomplete;  ///< why the recording is not whole (empty when it is)
  /// Why the discs' answer means nothing (empty when it holds): a rejected step, a tet turned
  /// inside out, a reaction beyond any physical one. The files are still written, to look at.
  std::string diverged;
  int steps = 0, frames = 0, discs = 0;
  long tets = 0;
  std::string resolution;  ///< the structured discs' (SpineDiscs::resolution)
  /// Simulated time; wall-clock of the steps alone, of the per-step measurements (reactions,
  /// volumes, inverted tets: one force evaluation a disc) and of the whole run.
  double simulated_s = 0, stepping_s = 0, measuring_s = 0, total_s = 0;
  /// Simulated over stepping time, and over stepping + measuring time.
  double speedup() const { return stepping_s > 0 ? simulated_s / stepping_s : 0; }
  double speedup_measured() const {
    return stepping_s > 0 ? simulated_s / (stepping_s + measuring_s) : 0;
  }
  std::vector<DiscPeaks> peaks;
  std::string pvd, table_csv, motion_csv, json;
};

/// Everything is checked (recording, tuned set, folder) before any file is written; a failure
/// later removes the half-written series. `progress(done, total)` every 100 steps.
SpineDiscsResult run_spine_discs(const SpineDiscsRequest& request, const std::string& data_dir,
                                 const std::function<void(int, int)>& progress = {});

/// The result's verdict: empty when every disc stepped and stayed physical, else why not.
std::string spine_discs_diverged(const SpineDiscsResult& r);

nlohmann::json spine_discs_json(const SpineDiscsResult& r);
std::string spine_discs_table(const SpineDiscsResult& r);

}  // namespace spinesim::studies
