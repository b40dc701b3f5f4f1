// spinesim demo — the pipeline on embedded defaults, with a report a person can read.
//
//   spinesim demo [--out demo-out]
//
// The steps are the demo driver's (studies/demo.hpp): mesh the L4-L5 disc between its
// vertebrae, its FEM reference, the material study, the untuned MSS against the FEM, the
// calibration protocol, the spine studies; VTU results, report.md, summary.json and report.html
// with plots in --out.
#include "cli_common.hpp"
#include "demo_screenshots.hpp"

#include "spinesim/studies/demo.hpp"

#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct DemoArgs {
  DemoRequest request;
  bool json = false, quiet = false, no_screenshots = false;
};

void run(const DemoArgs& a) {
  Progress progress(demo_stages(), a.quiet || a.json);
  DemoRequest request = a.request;
  if (!a.no_screenshots) request.viewer_screenshots = take_demo_screenshots;
  const DemoResult r = run_demo(request, progress.hooks());
  if (r.html.failed) throw std::runtime_error("--out " + request.out + ": " + r.html.message);
  if (a.json) {
    print_json(r.summary);
  } else {
    std::cout << demo_summary(r);
  }
}

}  // namespace

void register_demo(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand(
      "demo", "Run the pipeline on the embedded defaults and write a readable report");
  cmd->add_option("--out", a->request.out, "Output folder")->capture_default_str();
  cmd->add_option("--level", a->request.level, "Disc level")->capture_default_str();
  cmd->add_option("--cell-size", a->request.cell_size_mm, "Mesh cell size, mm")
      ->capture_default_str();
  cmd->add_option("--order", a->request.fem_order, "FEM element order 1 or 2")
      ->capture_default_str();
  cmd->add_flag("--no-screenshots", a->no_screenshots,
                "Leave the viewer's pictures out of the report (they run spinesim view under "
                "xvfb-run when there is no display)");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run(*a); });
}

}  // namespace spinesim::cli
