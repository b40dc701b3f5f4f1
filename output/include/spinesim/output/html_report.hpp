// The demo's HTML report with plots: scripts/report.py (python3-matplotlib, python3-markdown)
// run by Debian's /usr/bin/python3 on a folder the demo wrote (summary.json, haptic_plane.csv,
// haptics_stroke.csv, report.md), writing <folder>/report.html and <folder>/plots/*.png.
#pragma once

#include <string>

namespace spinesim::output {

struct HtmlReport {
  bool written = false;
  std::string path;     ///< <folder>/report.html
  std::string message;  ///< the script's one line: what it wrote, or why it wrote nothing
  /// The script ran and failed (not a missing tool, which it reports with status 2): a write
  /// that did not happen (a full disk) — the plots asked for are not all there, an error.
  bool failed = false;
};

/// Runs the report script (scripts/`script`: report.py for the demo, seating_report.py for the
/// seating studies) on `folder`. Never throws for the script's own failures (a missing
/// python3 or plotting library, bad input): they come back as written = false and one line.
HtmlReport write_html_report(const std::string& folder, const std::string& script = "report.py");

}  // namespace spinesim::output
