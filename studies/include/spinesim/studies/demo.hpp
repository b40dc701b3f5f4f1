// The whole pipeline on the embedded defaults, with a report a person can read (`spinesim demo`).
//
// Steps: 1. mesh the disc level between its vertebrae (thesis tables F.1/F.2 placement);
// 2. FEM reference (real-disc material): the 6x6 disc stiffness and the eight named load cases;
// 3. the material study (materials_study.hpp, thesis fig. 5.9); 4. the untuned mass-spring disc
// against that FEM on all eight cases (calibration/compare.hpp), and the probe test of thesis 5.3
// (probe_study.hpp, fig. 5.8) into <out>/probe; 5. the calibration protocol
// (calibration/protocol.hpp): Ipopt on four training cases, four held out; 6. the spine
// (spine_studies.hpp): validation (3.4), fusion (6.1) and trends (6.3-6.4); 7. VTU results,
// report.md and summary.json in the output folder; 8. report.html with plots (html_report.hpp).
#pragma once

#include "spinesim/mesh/mesher.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace spinesim::studies {

struct DemoRequest {
  std::string out = "demo-out";  ///< output folder (created)
  std::string level = "L4-L5";
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  int fem_order = 2;
  /// Pictures of the viewer for the report, made by the front end (which has the viewer) before
  /// report.html is written: given the output folder, it writes DIR/plots/view_*.png and
  /// DIR/viewer.json and returns one line saying what it did (empty: not asked for).
  std::function<std::string(const std::string&)> viewer_screenshots;
};

/// Progress stages of run_demo (for Progress).
int demo_stages();

struct DemoResult {
  std::string report_markdown;  ///< also written to <out>/report.md
  std::string report_path;
  nlohmann::json summary;   ///< also written to <out>/summary.json
  HtmlReport html;          ///< <out>/report.html, or why it was not written
  std::string viewer_note;  ///< what DemoRequest::viewer_screenshots did
};

/// Runs the steps above; throws std::invalid_argument for a bad request (unknown level, bad
/// order), std::runtime_error when a file cannot be written.
DemoResult run_demo(const DemoRequest& request, const StageHooks& hooks = StageHooks());

/// What the program prints when the demo is done (the report itself is in the files): the
/// headline numbers of each step — a dozen lines — and where the report is.
std::string demo_summary(const DemoResult& r);

}  // namespace spinesim::studies
