// Output files of the studies: atomic text files, output-folder checks before long runs, and a
// VTU time series of mass-spring states (ParaView .pvd + frames).
#pragma once

#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::studies {

/// Writes `text` to `path` completely or not at all (spinesim/common/atomic_file.hpp). Throws
/// std::runtime_error naming the file when the system refuses.
void write_text_file(const std::string& path, const std::string& text);

/// Throws std::invalid_argument "<option> <path>: folder … does not exist" unless `path`'s
/// folder exists (checked before long runs, so nothing is lost at the end).
void require_output_folder(const std::string& path, const std::string& option);

/// A VTU time series of MSS states: frames `<stem>/<stem>_NNNNNN.vtu` next to `<stem>.pvd`
/// (the PVD lists them relative to its folder). Frames are written as they come (atomically);
/// finish() writes the PVD; discard() removes every frame written (for a failed run). A series
/// destroyed before finish() — an exception, a full disk mid-way — discards itself: a run that
/// fails leaves no half series behind.
/// Point data `displacement` (mm), cell data `volume_change` (mss/quantities.hpp).
class VtuSeries {
 public:
  /// `pvd_path` ends in .pvd; its folder must exist; the frame folder is created.
  explicit VtuSeries(const std::string& pvd_path);
  ~VtuSeries();
  VtuSeries(const VtuSeries&) = delete;
  VtuSeries& operator=(const VtuSeries&) = delete;
  void add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm);
  void finish();
  void discard();
  const std::string& pvd_path() const { return pvd_path_; }
  std::size_t num_frames() const { return entries_.size(); }
  /// Caller-relative paths of the frames written.
  std::vector<std::string> frame_paths() const;

 private:
  std::string pvd_path_, folder_, stem_;
  std::vector<mesh::PvdEntry> entries_;
  bool finished_ = false;
};

}  // namespace spinesim::studies
