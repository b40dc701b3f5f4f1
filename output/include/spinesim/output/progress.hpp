// Progress on stderr — only on a terminal, so scripts see nothing but errors there.
//
//   Progress: numbered stages, one line each: "[2/4] assembling ... done, 0.42 s (35k DOF)".
//   ProgressBar: a loop of known length (all-level calibration, the database, sweeps), one line
//   redrawn in place: "  calibrating T7-T8  [#######.......]  7/17  41 %  ETA 1 min 12 s".
// Both are silent when told to be quiet (--quiet, --json) or when stderr is not a terminal.
#pragma once

#include "spinesim/common/timer.hpp"

#include <functional>
#include <string>

namespace spinesim::output {

/// True when stderr is a terminal (progress may be drawn).
bool stderr_is_terminal();

/// begin(what) before a stage, end(detail) after it; either may be empty. The drivers take
/// these so that a front end decides how (and whether) progress is shown.
struct StageHooks {
  std::function<void(const std::string& what)> begin;
  std::function<void(const std::string& detail)> end;
  void begin_stage(const std::string& what) const {
    if (begin) begin(what);
  }
  void end_stage(const std::string& detail = "") const {
    if (end) end(detail);
  }
};

class Progress {
 public:
  /// Prints only when not quiet and stderr is a terminal. `stages` <= 0: a count not known
  /// ahead (an iteration that stops when it settles), numbered without a total.
  Progress(int stages, bool quiet);
  void begin(const std::string& what);
  double end(const std::string& detail = "");  ///< returns the stage's seconds
  bool quiet() const { return quiet_; }
  /// Hooks that call begin() and end() of this object (which must outlive them).
  StageHooks hooks();

 private:
  int stages_, current_ = 0;
  bool quiet_;
  Timer timer_;
};

/// "1 min 12 s", "8.4 s", "2 h 05 min": a duration for people.
std::string human_duration(double seconds);

class ProgressBar {
 public:
  /// `total` steps; prints only when not quiet and stderr is a terminal.
  ProgressBar(int total, bool quiet, std::string unit = "");
  ~ProgressBar();  ///< clears the line
  /// `done` of `total` finished; `label` says what is being done now. Redraws at most every
  /// 0.1 s (and always at the end). The ETA is the mean time per step so far times the rest.
  void update(int done, const std::string& label = "");
  /// The line as it would be drawn (for tests): label, bar, count, percentage, ETA.
  static std::string render(int done, int total, double elapsed_s, const std::string& label,
                            const std::string& unit, int width = 24);
  /// A callback (done, total) for drivers that report counts (the database, sweeps); empty
  /// when quiet. The bar must outlive it.
  std::function<void(int, int)> callback();
  /// Clears the bar's line (the next output starts on a clean line).
  void finish();

 private:
  int total_;
  bool quiet_;
  std::string unit_;
  Timer timer_;
  double last_draw_s_ = -1;
  bool drawn_ = false;
};

}  // namespace spinesim::output
