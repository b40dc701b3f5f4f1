// spinesim spine schedule — loads that vary in time on any vertebra (CSV), solved as a
// quasi-static sequence (studies/spine_schedule.hpp); --record writes the vertebrae's motions
// for `spine discs --record`, so the offline discs follow the schedule.
//
//   spinesim spine schedule --loads examples/load-schedule/lift.csv --step 0.5 --csv out.csv
#include "cli_common.hpp"

#include "spinesim/studies/spine_schedule.hpp"

#include <filesystem>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct ScheduleArgs {
  std::string loads, csv, record, out, fusion, disc_joints, ligaments = "auto";
  double step_s = 0, dt_s = 0.005, damping_ratio = 0;
  bool dynamic = false;
  int workers = 0;
  bool json = false, quiet = false, no_muscles = false, rib_cage = false;
  SubjectFlags subject;
  ScoliosisFlags scoliosis;
};

void run_schedule(const ScheduleArgs& a) {
  // Every input checked before any solve; nothing is written on bad input.
  if (!(a.step_s >= 0)) throw std::invalid_argument("--step must be a number >= 0 s");
  if (a.dynamic && !(a.dt_s > 0 && a.dt_s <= 0.05))
    throw std::invalid_argument("--dt must lie in (0, 0.05] s");
  if (a.dynamic && !(a.damping_ratio >= 0 && a.damping_ratio <= 1))
    throw std::invalid_argument("--damping-ratio must lie in [0, 1]");
  if (!a.dynamic && (a.dt_s != 0.005 || a.damping_ratio != 0))
    throw std::invalid_argument("--dt and --damping-ratio are for --dynamic");
  if (a.workers < 0) throw std::invalid_argument("--workers must be >= 0");
  const LoadSchedule schedule = read_load_schedule(a.loads);
  spine::ModelOptions model;
  if (!a.fusion.empty()) model.fused_joints = spine::parse_fusion(a.fusion);
  model.muscles = !a.no_muscles;
  model.disc_joints = a.disc_joints;
  model.ligaments = spine::parse_ligaments(a.ligaments);
  model.rib_cage = a.rib_cage;
  model.subject = spine::resolve_subject(data_dir(), subject_of(a.subject));
  model.scoliosis = scoliosis_of(a.scoliosis);
  if (a.step_s > 0 &&
      (schedule.time_s.back() - schedule.time_s.front()) / a.step_s > 1e5)
    throw std::invalid_argument("--step " + fixed(a.step_s, 6) +
                                " s samples the schedule more than 100000 times");
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");
  if (!a.record.empty()) require_output_folder(a.record, "--record");
  if (!a.out.empty()) prepare_output_folder(a.out, "--out");
  spine::SolveOptions solve;
  solve.recruit = !a.no_muscles;

  std::unique_ptr<ProgressBar> bar;
  ScheduleRun run =
      run_load_schedule(data_dir(), schedule, model, solve, a.step_s, a.workers,
                        [&](int done, int total) {
                          if (!bar)
                            bar = std::make_unique<ProgressBar>(total, a.quiet || a.json,
                                                                "equilibria");
                          bar->update(done, "solving the schedule");
                        });
  if (bar) bar->finish();
  if (a.dynamic) {
    spine::DynamicsOptions d;
    d.dt_s = a.dt_s;
    d.damping_ratio = a.damping_ratio;
    if (!a.quiet && !a.json) std::cerr << "integrating the motion ..." << std::endl;
    run_schedule_dynamics(run, d);
  }
  if (!a.csv.empty()) write_csv_file(a.csv, schedule_csv(run));
  if (!a.record.empty()) write_schedule_recording(run, a.record);
  if (!a.out.empty()) {
    namespace fs = std::filesystem;
    write_json_file((fs::path(a.out) / "schedule.json").string(), schedule_json(run));
    write_csv_file((fs::path(a.out) / "schedule.csv").string(), schedule_csv(run));
    const HtmlReport r = write_html_report(a.out, "schedule_report.py");
    if (r.failed) throw std::runtime_error("--out " + a.out + ": " + r.message);
    std::cerr << (r.written ? "" : "spinesim: warning: ") << r.message << std::endl;
  }
  if (a.json)
    print_json(schedule_json(run));
  else
    print_schedule(std::cout, run);
  if (run.failed)
    std::cerr << "spinesim: warning: " << run.failed << " of " << run.steps.size()
              << " steps reached no equilibrium (kept, marked converged = 0)" << std::endl;
}

}  // namespace

void register_spine_schedule(CLI::App& spine) {
  auto a = std::make_shared<ScheduleArgs>();
  auto* cmd = spine.add_subcommand(
      "schedule",
      "Loads that vary in time on any vertebra (a CSV schedule), solved as a quasi-static "
      "sequence");
  cmd->add_option("--loads", a->loads,
                  "Schedule CSV: time_s, then VERTEBRA.COMPONENT columns (fx_n fy_n fz_n in N at "
                  "the vertebra's centre, mx_nmm my_nmm mz_nmm couples in N·mm); times "
                  "increasing, no empty cells; linear between rows")
      ->required();
  cmd->add_option("--step", a->step_s,
                  "Also solve every this many seconds between the rows, s (0: the rows only)")
      ->capture_default_str();
  cmd->add_flag("--dynamic", a->dynamic,
                "Also integrate the motion (inertia; spine/README.md): from the first step at "
                "rest, the muscles held as each step recruited them; shown beside the "
                "quasi-static answer at every sampled time");
  cmd->add_option("--dt", a->dt_s, "--dynamic: time step, s")->capture_default_str();
  cmd->add_option("--damping-ratio", a->damping_ratio,
                  "--dynamic: stiffness-proportional damping, this ratio at the first mode (0: "
                  "undamped, the bound the inertia check uses)")
      ->capture_default_str();
  cmd->add_option("--csv", a->csv,
                  "One row per time: loads, every joint's forces, every vertebra's motion");
  cmd->add_option("--record", a->record,
                  "Write the vertebrae's motions as a spine recording for `spine discs --record`");
  cmd->add_option("--out", a->out,
                  "Write schedule.json, schedule.csv, a plot of the loads, the discs' forces and "
                  "T1's motion over time, and report.html into this folder");
  cmd->add_option("--workers", a->workers, "Threads (0: one per core)")->capture_default_str();
  cmd->add_option("--fusion", a->fusion, "Fused levels, e.g. L3-L4 or L3-L4-L5");
  cmd->add_flag("--no-muscles", a->no_muscles, "Passive spine: no muscles");
  cmd->add_option("--disc-joints", a->disc_joints,
                  "Joint springs from each level's disc (a data/spine/disc_joints/ preset or a "
                  "file) in place of F.4");
  add_ligaments_option(cmd, a->ligaments);
  add_rib_cage_option(cmd, a->rib_cage);
  add_scoliosis_options(cmd, a->scoliosis);
  add_subject_options(cmd, a->subject);
  add_output_flags(cmd, a->json, a->quiet, "every step as JSON");
  cmd->footer(
      "Quasi-static: the model is elastic and keeps no history, so each time is its own "
      "equilibrium (muscles\nrecruited for the loads of that moment) and the answer does not "
      "depend on the sampling. Inertia is\nnot modelled. A step without equilibrium is kept "
      "(converged = 0, a warning); the others go on.");
  cmd->callback([a] { run_schedule(*a); });
}

}  // namespace spinesim::cli
