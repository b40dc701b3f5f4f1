// Output files of the studies: atomic text files, output-folder checks before long runs, and a
// VTU time series of mass-spring states (ParaView .pvd + frames).
#pragma once

#include "spinesim/common/pending_output.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mss/model.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace spinesim::output {

/// Writes `text` to `path` completely or not at all (spinesim/common/atomic_file.hpp). Throws
/// std::runtime_error naming the file when the system refuses.
void write_text_file(const std::string& path, const std::string& text);

/// `j` written as JSON (indented by `indent`, a final newline), atomically, with the run's
/// provenance (spinesim/common/provenance.hpp) under "provenance" when `j` is an object.
void write_json_file(const std::string& path, const nlohmann::json& j, int indent = 2);

/// A CSV table written atomically after the provenance line "# provenance: {…}" (readers that
/// skip '#' lines — ours, numpy, pandas with comment='#' — see the table as before).
void write_csv_file(const std::string& path, const std::string& csv);

/// The run's provenance as a markdown section ("## Provenance": program, commit, command,
/// folder, the inputs' sizes and SHA-256), for the end of a markdown report; "" outside a run.
std::string markdown_provenance();

/// Throws std::invalid_argument "<option> <path>: folder … does not exist" unless `path`'s
/// folder exists (checked before long runs, so nothing is lost at the end).
void require_output_folder(const std::string& path, const std::string& option);

/// The one rule of every folder output (`--out DIR`): the folder is made, parents and all, before
/// the work starts; refused (std::invalid_argument "<option> <path>: …", one line) only when it
/// cannot be: a file, a device or a link to one is in the way, or the system says no (no
/// permission, a read-only or full file system — checked by making and removing a probe file).
void prepare_output_folder(const std::string& path, const std::string& option);

/// A VTU time series of MSS states: frames `<stem>/<stem>_NNNNNN.vtu` next to `<stem>.pvd`
/// (the PVD lists them relative to its folder). Frames are written as they come (each
/// atomically) into a staging folder `<stem>.staged-PID/` beside the PVD; finish() moves them
/// into `<stem>/` — replacing the frames of an earlier series of the same name, and removing
/// those of its frames this series does not have — then writes the PVD, with the catchable
/// signals held back, so that the folder and the PVD always describe one complete series.
/// discard() removes the staging folder; a series destroyed before finish() (an exception, a
/// full disk mid-way) discards itself, and a run killed before it removes the staging folder
/// (spinesim/common/pending_output.hpp): a run that fails leaves no half series behind, and an
/// earlier series stays whole until the new one is complete.
/// Point data `displacement` (mm), cell data `volume_change` (mss/quantities.hpp).
class VtuSeries {
 public:
  /// `pvd_path` ends in .pvd; its folder must exist; the frame folder is created.
  explicit VtuSeries(const std::string& pvd_path);
  ~VtuSeries();
  VtuSeries(const VtuSeries&) = delete;
  VtuSeries& operator=(const VtuSeries&) = delete;
  void add(double time_s, const mss::MssModel& model, const Eigen::VectorXd& x_mm);
  /// A frame of part `part` (>= 0) written by `write` to the staging path it is given (a VTU);
  /// every part's times must increase.
  void add(double time_s, int part, const std::function<void(const std::string&)>& write);
  void finish();
  void discard();
  const std::string& pvd_path() const { return pvd_path_; }
  std::size_t num_frames() const { return entries_.size(); }
  /// Caller-relative paths of the frames written.
  std::vector<std::string> frame_paths() const;

 private:
  std::string pvd_path_, folder_, staging_, stem_;
  std::vector<mesh::PvdEntry> entries_;
  PendingOutput pending_;  ///< the staging folder, until finish() or discard()
  bool finished_ = false;
};

}  // namespace spinesim::output
