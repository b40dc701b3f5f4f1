// The `--record` file of `spinesim haptics run` (docs/file-formats.md "Haptic recordings"):
// CSV, one row per servo tick, written while the loop runs — appended in blocks by the loop's
// writer thread, each block flushed and synced to disk (fdatasync), so a run killed at any moment
// leaves a file that reads up to its last synced block. A clean end appends the line
// "# end: N ticks"; the reader says when it is missing.
//
// Columns: t_s,x_mm,y_mm,z_mm,button (a trajectory: `--device replay` plays them), the force on
// the hand, the proxy, contact, the tick number; with the compliant stage also the hook
// (attached, vertebra, world point, the force on the spine) and every vertebra's rigid motion
// from the reference posture: its F.1 centre's displacement (mm) and its rotation vector (deg).
// On a 6-DOF device the row ends with the stylus's rotation vector (deg: `rx_deg,ry_deg,rz_deg`,
// which --device replay plays too) and the commanded torque (N·mm), and with the compliant stage
// the hook's moment on the spine (N·mm).
// The header names the spine model by a fingerprint of its geometry, so a recording is never
// replayed on another model.
#pragma once

#include "spinesim/haptics/servo.hpp"
#include "spinesim/spine/model.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace spinesim::haptics {

/// 16 hex digits (FNV-1a) over the model's vertebra centres, joint points and fused joints.
std::string spine_model_fingerprint(const spine::SpineModel& m);

class HapticRecordingWriter {
 public:
  /// Opens `path` (replacing a file there) and writes the header. `model` is null without the
  /// compliant stage. Throws std::runtime_error when the file cannot be written.
  /// `disc`: disc palpation columns after the common ones (disc_contact, the simulated probe,
  /// the disc's force on it, its volume change).
  HapticRecordingWriter(const std::string& path, const std::string& description,
                        const spine::SpineModel* model, const std::string& response,
                        bool disc = false, bool six_dof = false);
  ~HapticRecordingWriter();
  /// Appends rows, flushes and syncs them (the loop's writer thread).
  void append(const haptics::TickRecord* rows, std::size_t n);
  /// Appends the end line — "# end: N ticks", and "; stopped early: WHY" when `stopped_early`
  /// says why the run did not end by itself (a signal, an error) — and closes. Throws
  /// std::runtime_error on a failed write, after removing the file.
  void finish(const std::string& stopped_early = "");
  std::int64_t rows() const { return rows_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::vector<Eigen::Vector3d> centres_;
  std::int64_t rows_ = 0;
  bool disc_ = false, six_dof_ = false;
  bool failed_ = false;
};

/// One recorded tick of a compliant-stage run.
struct DragFrame {
  double t_s = 0;
  std::int64_t tick = 0;
  bool attached = false;
  int hook_vertebra = -1;
  Eigen::Vector3d probe_mm, proxy_mm, hand_force_n, hook_mm, spine_force_n;
  Eigen::Vector3d hook_ref_mm;  ///< the hook point in its vertebra's reference coordinates
  /// 6-DOF recordings (zero otherwise): the stylus's rotation vector (deg), the torque on the
  /// hand (N·mm), the hook's moment on the spine (N·mm).
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero(), torque_nmm = Eigen::Vector3d::Zero(),
                  spine_moment_nmm = Eigen::Vector3d::Zero();
  /// Per vertebra T1…L5: centre displacement (mm), rotation vector (deg).
  Eigen::Matrix<double, 17, 6> motion;
  /// The rigid motion of vertebra i (x ↦ R x + t, reference coordinates).
  spine::Pose pose(const spine::SpineModel& m, int i) const;
};

struct DragRecording {
  std::string path, fingerprint, response;
  bool six_dof = false;  ///< the header names the 6-DOF columns
  std::vector<DragFrame> frames;
  /// The run ended by itself and its end line counts exactly the rows read (false: a killed or
  /// stopped run, read to its last whole row; incomplete_reason says which).
  bool complete = false;
  std::string incomplete_reason;
};

/// The end line's start, and the bounds of a recorded vertebra motion (a corrupt row beyond them
/// is refused): no spine moves a vertebra half a metre or turns it past half a turn.
inline constexpr const char* kEndLine = "# end: ";
inline constexpr double kMaxVertebraShiftMm = 500, kMaxVertebraTurnDeg = 180;

/// Reads a compliant-stage recording for `model`. Throws std::invalid_argument with one line for
/// a file that is not one (no spine columns), one from another spine model, missing ticks (a
/// gap in the tick numbers), a bad number, a hook force beyond what the spine solve accepts
/// (spine::kMaxForceN), a vertebra beyond the bounds above, or fewer than two rows. A last line
/// cut off mid-row (a killed run) is dropped.
DragRecording read_drag_recording(const std::string& path, const spine::SpineModel& model);

/// Whose spine a compliant-stage recording dragged: the body (its "# body:" line; without one
/// the reference body's: zeros) and the scoliotic curve it rested in (its "# scoliosis:" line;
/// without one straight: cobb_deg 0).
struct RecordedSpine {
  spine::Subject subject;
  spine::ScoliosisCurve scoliosis;
};
/// Reads the header only; std::invalid_argument (one line) for a malformed body or scoliosis
/// line or a curve the model cannot pose.
RecordedSpine recording_spine(const std::string& path);

}  // namespace spinesim::haptics
