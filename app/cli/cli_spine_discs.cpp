// spinesim spine discs — the hybrid spine offline (thesis 5.4, 6.4): the 17 tuned structured discs
// simulated between the vertebra poses of a compliant-stage recording
// (studies/spine_discs.hpp).
//
//   spinesim haptics run --scene spine --device sim --script data/haptics/drag_t1_lateral.csv \
//       --record drag.csv
//   spinesim spine discs --record drag.csv --out discs-out [--params real-disc|fibre-reinforced|SET.json]
#include "cli_common.hpp"

#include "spinesim/studies/spine_discs.hpp"

#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct DiscsArgs {
  studies::SpineDiscsRequest request;
  bool json = false, quiet = false;
};

void run_discs(const DiscsArgs& a) {
  std::unique_ptr<ProgressBar> bar;  // the number of ticks is known once the recording is read
  const SpineDiscsResult r = run_spine_discs(a.request, data_dir(), [&](int done, int total) {
    if (!bar) bar = std::make_unique<ProgressBar>(total, a.quiet || a.json, "ticks");
    bar->update(done, "stepping the discs");
  });
  if (bar) bar->finish();
  if (a.json)
    print_json(spine_discs_json(r));
  else
    std::cout << spine_discs_table(r);
  // Checked before the program says it succeeded: the summary is out, the verdict is the status.
  if (!r.diverged.empty())
    throw std::runtime_error("the discs diverged: " + r.diverged + " (the series is written)");
}

}  // namespace

void register_spine_discs(CLI::App& spine) {
  auto a = std::make_shared<DiscsArgs>();
  auto* cmd = spine.add_subcommand(
      "discs",
      "The hybrid spine offline: the 17 tuned mass-spring discs between the vertebra poses of a "
      "compliant-stage recording (ParaView series, per-disc table)");
  cmd->add_option("--record", a->request.recording,
                  "Compliant-stage recording (`haptics run --scene spine --record`)")
      ->required();
  cmd->add_option("--out", a->request.out, "Output folder (created; its parent must exist)")
      ->required();
  cmd->add_option("--params", a->request.tuned,
                  "Tuned set of the structured discs: real-disc (default; the linear "
                  "calibration, data/tuned_structured_discs.json), fibre-reinforced (the fibre "
                  "networks of the nonlinear disc, data/tuned_structured_fibre_discs.json) or a "
                  "file; each level must have been calibrated on its structured disc");
  cmd->add_option("--frame-period", a->request.frame_period_s,
                  "A ParaView frame and disc_motion.csv rows every this many seconds")
      ->capture_default_str();
  cmd->add_option("--vertebra-triangles", a->request.vertebra_triangles,
                  "Triangles per vertebra surface in the series (0: discs only)")
      ->capture_default_str();
  cmd->add_option("--threads", a->request.threads, "Discs stepped in parallel (0: one per core)")
      ->capture_default_str();
  cmd->add_option("--newton-iterations", a->request.newton_iterations,
                  "Newton iterations per implicit step")
      ->capture_default_str();
  cmd->add_flag("--refactorize", a->request.refactorize,
                "Refactorise the matrix every Newton iteration (default: the rest factorisation "
                "is kept; ~50x slower)");
  add_output_flags(cmd, a->json, a->quiet, "the summary and per-disc table as JSON");
  cmd->footer(
      "Each disc: the level's structured disc at the resolution its set was calibrated on "
      "(real-disc:\n12 sectors x 3 rings x 2 layers) in the spine frame, inferior\nendplate on the "
      "lower vertebra, superior on the upper (the sacrum fixed), "
      "implicit Euler at 1 ms\n(one step per recorded tick), started at its static equilibrium "
      "in the first recorded posture.\nWritten: OUT/spine.pvd (part 0 discs: displacement, "
      "volume_change, spring_strain, disc; part 1\nvertebrae), OUT/discs.csv (peaks per disc), "
      "OUT/disc_motion.csv, OUT/discs.json.");
  cmd->callback([a] { run_discs(*a); });
}

}  // namespace spinesim::cli
