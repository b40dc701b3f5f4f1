// The compliant-stage study (thesis 4.5, 6.3): a scripted hand drags T1 (laterally, sagittally or
// obliquely, data/haptics/drag_t1_*.csv) with each spine response in turn — the multirate spine
// and the thesis's displacement–force database — recording every tick; then, at sampled ticks
// while hooked, the recorded vertebra motions are compared with direct equilibrium solves at the
// recorded hook force and point: the pose error of each method. Also written: the relative
// translation and rotation of every vertebra pair over the drag (figs 6.12–6.25, 6.38–6.47), and
// the 17 offline discs driven by the multirate recording (`spine discs`).
#pragma once

#include "spinesim/studies/haptics_run.hpp"
#include "spinesim/studies/spine_discs.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace spinesim::studies {

struct HapticDragRequest {
  std::vector<std::string> cases = {"lateral", "sagittal", "oblique"};
  std::vector<std::string> methods = {"multirate", "database"};
  std::string out;                ///< folder for the recordings and CSVs (must exist)
  double sample_every_s = 0.1;    ///< direct solves this often while hooked
  double min_force_n = 5;         ///< samples below this hook force are skipped
  bool realtime_priority = true;  ///< for the haptic runs
  int triangles = 5000;           ///< per generated vertebra
  /// Also drive the 17 offline discs with each case's multirate recording (spine_discs.hpp) into
  /// <out>/discs_<case>/ (thesis 5.4, 6.4).
  bool discs = true;
};

/// Percentiles over the samples of one vertebra's error.
struct ErrorPercentiles {
  double p50 = 0, p95 = 0, max = 0;
};

struct DragMethodResult {
  std::string method, recording;
  haptics::ServoStats stats;
  double worker_rate_hz = 0;
  int samples = 0, failed_solves = 0;
  double hook_motion_max_mm = 0;  ///< the largest direct motion of the hook vertebra's centre
  /// Per vertebra T1…L5: centre position error (mm) and rotation error (deg) against direct solves,
  /// and the position error as a percentage of the hook vertebra's largest direct motion.
  std::array<ErrorPercentiles, 17> translation_mm{}, rotation_deg{}, relative_percent{};
};

struct DragCaseResult {
  std::string name;
  std::vector<DragMethodResult> methods;
  std::string pairs_csv;  ///< path of the vertebra-pair motions (from the multirate run)
  bool has_discs = false;
  SpineDiscsResult discs;  ///< the offline discs of the multirate recording
};

struct HapticDragResult {
  HapticDragRequest request;
  std::vector<DragCaseResult> cases;
  double seconds = 0;
};

/// Throws std::invalid_argument (one line) for an unknown case or method, a missing folder.
HapticDragResult run_haptic_drag_study(const HapticDragRequest& request,
                                       const std::string& data_dir,
                                       const std::function<void(const std::string&)>& stage = {});

nlohmann::json haptic_drag_json(const HapticDragResult& r);
std::string haptic_drag_table(const HapticDragResult& r);

}  // namespace spinesim::studies
