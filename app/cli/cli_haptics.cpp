// spinesim haptics run | devices, and spinesim study haptic-plane.
//
//   spinesim haptics run --scene spine|vertebra|plane [--vertebrae generated]
//       --device sim|replay|null|openhaptics|dhd [--script TRAJ.csv | --replay REC.csv]
//       [--duration S] [--probe-radius MM] [--renderer proxy|gao-gibson] [--record REC.csv] [--json]
//   spinesim haptics devices
//   spinesim study haptic-plane [--csv]
//   spinesim study haptic-drag [--case lateral|sagittal|oblique] --out DIR [--json]
//
// Ctrl-C (or SIGTERM/SIGHUP/QUIT) during a run ends the loop: the force goes to zero, the device
// is closed, the summary is printed, then the run exits by the signal.
#include "cli_common.hpp"
#include "spinesim/studies/seating_study.hpp"

#include "spinesim/mesh/vertebra_cache.hpp"
#include "spinesim/studies/haptic_drag_study.hpp"
#include "spinesim/studies/haptic_plane_study.hpp"
#include "spinesim/studies/haptics_run.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

void on_stop_signal(int sig) {
  g_signal.store(sig);
  g_stop.store(true);
}

// While alive, the terminating signals end the haptic loop instead of the process.
class StopOnSignals {
 public:
  StopOnSignals() {
    for (std::size_t i = 0; i < 4; ++i) {
      struct sigaction sa {};
      sa.sa_handler = on_stop_signal;
      sigemptyset(&sa.sa_mask);
      ::sigaction(kSignals[i], &sa, &old_[i]);
    }
  }
  ~StopOnSignals() {
    for (std::size_t i = 0; i < 4; ++i) ::sigaction(kSignals[i], &old_[i], nullptr);
    if (const int sig = g_signal.load()) std::raise(sig);  // now the previous handler's turn
  }

 private:
  static constexpr int kSignals[4] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  struct sigaction old_[4]{};
};

struct HapticsArgs {
  HapticsRunFlags flags;
  bool json = false, quiet = false;
};

void run_haptics_cli(HapticsArgs& args) {
  resolve_haptics_run_flags(args.flags);
  struct {
    HapticsRunRequest& request;
    bool json, quiet;
  } a{args.flags.request, args.json, args.quiet};
  a.request.stop = &g_stop;
  const bool live = !a.quiet && !a.json && stderr_is_terminal();
  std::unique_ptr<ProgressBar> bar;
  if (a.request.scene.scene != "plane")
    bar = std::make_unique<ProgressBar>(a.request.scene.scene == "spine"  ? 18
                                        : a.request.scene.scene == "disc" ? 2
                                                                          : 1,
                                        a.quiet || a.json, "vertebrae meshed");
  HapticsRunResult result;
  {
    const StopOnSignals stop;
    result = run_haptics(
        a.request, data_dir(),
        [live](const haptics::ServoStatus& s) {
          if (!live) return;
          if (s.disc)
            std::fprintf(stderr,
                         "\r  t %6.1f s | %6.1f Hz | felt %5.2f N | disc %s, load %6.1f N, "
                         "indented %5.2f mm, volume %+7.3f %%  ",
                         s.time_s, s.time_s > 0 ? double(s.ticks) / s.time_s : 0.0,
                         s.force_n.norm(), s.disc_contact ? "pressed" : "free   ",
                         s.disc_force_n.norm(), s.disc_indentation_mm, 100 * s.disc_volume_change);
          else if (s.hook.attached || s.hook.gain > 0)
            std::fprintf(
                stderr,
                "\r  t %6.1f s | %6.1f Hz | force %5.2f N | hooked %s, spine %6.1f N, %5.2f N m, "
                "torque %5.1f N mm  ",
                s.time_s, s.time_s > 0 ? double(s.ticks) / s.time_s : 0.0, s.force_n.norm(),
                spine::vertebra_names()[std::size_t(std::max(0, s.hook.load.vertebra))].c_str(),
                s.hook.load.force_n.norm(), s.hook.load.moment_nmm.norm() / 1000,
                s.torque_nmm.norm());
          else
            std::fprintf(stderr, "\r  t %6.1f s | %6.1f Hz | force %5.2f N | %s        ", s.time_s,
                         s.time_s > 0 ? double(s.ticks) / s.time_s : 0.0, s.force_n.norm(),
                         s.contact ? "contact" : "free   ");
          std::fflush(stderr);
        },
        [&bar](int done, int) {
          if (g_stop.load()) throw std::runtime_error("interrupted while the scene was built");
          if (bar) bar->update(done);
        });
    if (live) std::fprintf(stderr, "\r%78s\r", "");
    if (a.json)
      print_json(haptics_run_json(result));
    else
      std::cout << haptics_run_table(result);
    std::cout.flush();
    if (result.stats.error)
      throw std::runtime_error("the loop stopped on an error, the force set to zero: " +
                               result.stats.stop_reason);
  }
  // Still here after a stop signal: it was ignored when the run started (a background job's
  // SIGINT), so re-raising it did nothing. A stopped run is not a finished one.
  if (const int sig = g_signal.load())
    throw std::runtime_error("stopped by signal " + std::to_string(sig) +
                             " before the end (the force was set to zero)");
  const std::string missed = missed_deadlines_warning(result, args.flags.max_missed_percent);
  if (!missed.empty() && args.flags.strict) throw std::runtime_error(missed + " (--strict)");
  if (!missed.empty()) std::cerr << "spinesim: warning: " << missed << "\n";
}

struct PlaneArgs {
  HapticPlaneRequest request;
  bool csv = false, json = false, quiet = false;
  std::string out;
};

void run_plane(const PlaneArgs& a) {
  const auto result = run_haptic_plane_study(a.request);
  if (!a.out.empty()) write_csv_file(a.out, haptic_plane_csv(result));
  if (a.json)
    print_json(haptic_plane_json(result));
  else if (a.csv)
    std::cout << haptic_plane_csv(result);
  else
    std::cout << haptic_plane_table(result);
}

}  // namespace

/// The disc scene's flags of `haptics run`.
void add_disc_flags(CLI::App* run, HapticsRunRequest& request) {
  run->add_option("--level", request.scene.level, "--scene disc: the disc level (T1-T2 ... L5-S1)")
      ->capture_default_str();
  run->add_option("--params", request.disc_params,
                  "--scene disc: tuned set or tuned.json, or a shipped set: fibre-reinforced "
                  "(the default: the nonlinear fibre disc's fibre network, "
                  "data/tuned_fibre_discs.json) or real-disc (the linear isotropic disc's, "
                  "data/tuned_discs.json)");
  run->add_option("--disc-solver", request.disc_solver,
                  "--scene disc: multirate (the disc stepped every --disc-period-ms on its "
                  "thread, its local contact model felt every tick; meshes >= 20,000 tets) or "
                  "direct (the disc stepped every 1 ms tick; a few thousand tets)")
      ->capture_default_str();
  run->add_option("--disc-model", request.disc_model,
                  "--scene disc: mss (the tuned mass-spring disc) or fem (the linear FEM disc the "
                  "tuned set was matched to, on the same mesh: static, its compliance at the "
                  "probe solved as the probe moves)")
      ->capture_default_str();
  run->add_option("--disc-period-ms", request.disc_period_ms,
                  "--disc-solver multirate: the disc's step, 1 to 10 ms")
      ->capture_default_str();
  run->add_option("--disc-budget-us", request.disc_budget_us,
                  "--scene disc: the disc step's CPU p99 must fit this (default: 80 % of the "
                  "period, multirate, from 1.5, 2, 2.5, 3 mm cells; 500 us, direct, from 2, 2.5, "
                  "3, 4 mm); at start the finest mesh that does is chosen");
  run->add_flag("--disc-sync-check", request.disc_sync_check,
                "--disc-solver multirate: after the run, step the disc every 1 ms along the "
                "recorded hand path (off the clock: ~5 s per second at 20,000 tets) and report "
                "the felt force's error against it");
  run->add_option("--disc-cell-size", request.disc_cell_size_mm,
                  "--scene disc: use this CGAL cell size (mm) instead of the budget check's "
                  "choice (its step is still measured and reported)");
}

void add_scene_flags(CLI::App* cmd, haptics::HapticSceneRequest& scene) {
  cmd->add_option("--scene", scene.scene,
                  "spine (T1-L5 and sacrum), vertebra (L3), disc (a tuned disc between its two "
                  "vertebrae, --level) or plane")
      ->capture_default_str();
  cmd->add_option("--vertebrae", scene.vertebrae,
                  "Vertebra surfaces: generated (parametric), real (ArtiSynth L1-S1 from the test "
                  "data, thoracic generated) or a scene JSON file (haptics/README.md)")
      ->capture_default_str();
  cmd->add_option("--testdata", scene.testdata_dir,
                  "Folder holding artisynth-lss/ (for --vertebrae real; default: "
                  "$SPINESIM_TESTDATA_DIR or the shared test-data folder)");
  cmd->add_option("--triangles", scene.triangles, "Triangles per generated vertebra")
      ->capture_default_str();
  scene.cache_dir = mesh::default_cache_dir();
  cmd->add_option("--cache-dir", scene.cache_dir,
                  "Folder where generated vertebrae are kept between runs, so that a run starts "
                  "in about a second (none: mesh them every time)")
      ->capture_default_str();
}

namespace {

/// The compliant stage's flags (--spine and what goes with it).
void add_compliant_stage_flags(CLI::App* cmd, HapticsRunFlags& f) {
  cmd->add_option("--spine", f.request.spine,
                  "Compliant stage (--scene spine): press the stylus button on a vertebra to drag "
                  "it; multirate (equilibrium solves in a worker + their sensitivity) or database "
                  "(the thesis's displacement-force polynomials)");
  cmd->add_option("--database", f.request.database,
                  "--spine database: the database file (default data/spine/displacement_db.json)");
  cmd->add_option("--force-scale", f.request.force_scale,
                  "Spine or disc force per felt force, N/N (default: 600 N on the spine, 100 N on "
                  "the disc, at the device's peak force)");
  cmd->add_option("--coupling-stiffness", f.request.coupling_stiffness_n_per_mm,
                  "Felt stiffness of the hook spring (--spine) or of the disc coupling (--scene "
                  "disc), N/mm (default: the rendering stiffness)");
  cmd->add_option("--coupling-damping", f.request.coupling_damping_n_s_per_mm,
                  "Felt damping of the hook spring or the disc coupling, N*s/mm (0: none; the "
                  "FEM disc's coupling gets k_c T / 2, the least that keeps a sampled spring "
                  "passive)")
      ->capture_default_str();
  cmd->add_option("--rotational-stiffness", f.request.rotational_stiffness_nmm_per_rad,
                  "--spine multirate on a 6-DOF device with torque (--model sigma.7, "
                  "premium-1.5-6dof): the hook's torsional spring, felt, N*mm/rad; the stylus's "
                  "turn twists the hooked vertebra and the hand feels the spine's moment / "
                  "--force-scale (default: the device's usable rotational stiffness; 0: off)");
  cmd->add_flag("--no-recruit{false}", f.request.spine_recruit,
                "--spine multirate: passive spine solves (muscles off)");
  add_scoliosis_options(cmd, f.scoliosis);
  cmd->add_option("--body-height", f.body.height_m,
                  "--scene spine: body height, m (default: the reference body, 1.778 m); the "
                  "spine and its surfaces scale with it (spine/README.md)");
  cmd->add_option("--body-mass", f.body.mass_kg, "--scene spine: body mass, kg (default 70)");
  cmd->add_option("--sex", f.body.sex, "--scene spine: male or female")
      ->check(CLI::IsMember({"male", "female"}))
      ->capture_default_str();
  add_named_subject_option(cmd, f.body, "--body-height, --body-mass or --sex (--scene spine)");
  cmd->add_flag("--rib-cage", f.request.scene.rib_cage,
                "--scene spine: add the ribs and the sternum (drawn and touched); with --spine "
                "they stiffen the thorax and move with it (--spine database: a database built "
                "with `spine database --rib-cage`)");
  cmd->add_option("--posture", f.request.posture,
                  "--spine multirate: standing, or seated in a chair (study seating's model; "
                  "--chair, --backrest-recline, --lumbar-support)")
      ->capture_default_str();
  cmd->add_option("--chair", f.chair_file,
                  "--posture seated: the backrest as a surface file (STL, OBJ; mm; see study "
                  "seating --help)");
  cmd->add_option("--backrest-recline", f.request.chair.backrest_recline_deg,
                  "--posture seated: backrest angle to the horizontal, deg")
      ->capture_default_str();
  cmd->add_option("--lumbar-support", f.request.chair.lumbar_support_mm,
                  "--posture seated: lumbar pad depth, mm")
      ->capture_default_str();
}

}  // namespace

void add_haptics_run_flags(CLI::App* cmd, HapticsRunFlags& f, bool viewer) {
  add_scene_flags(cmd, f.request.scene);
  add_disc_flags(cmd, f.request);
  cmd->add_option("--device", f.request.device,
                  viewer
                      ? "mouse (the pointer is the probe's hand), sim, replay, null, openhaptics, "
                        "dhd, or none (the scene alone)"
                      : "sim, replay, null, openhaptics or dhd (mouse: in spinesim view)")
      ->capture_default_str();
  cmd->add_option("--model", f.request.model,
                  "Device capability record: touch, premium-1.5, omega.3; 6-DOF: sigma.7, "
                  "premium-1.5-6dof (torque), omega.6 (turn sensed, no torque) (peak force and "
                  "torque, stiffness; haptics devices lists them)")
      ->capture_default_str();
  cmd->add_option("--script", f.request.script,
                  "sim: the hand's set-point trajectory, CSV t_s,x_mm,y_mm,z_mm[,button] "
                  "(default: data/haptics/ for the scene), or hostile:NAME, a trajectory built "
                  "to break the tick's bounds (teleport, start-inside, sweep, skim, shake, "
                  "hammer; haptics/README.md)");
  cmd->add_option("--replay", f.request.replay, "replay: a file written by --record");
  cmd->add_option("--sdk-lib", f.request.sdk_library,
                  "openhaptics/dhd: the vendor's shared library (default libHD.so / libdhd.so)");
  cmd->add_option("--workspace-center", f.workspace_center,
                  "openhaptics/dhd: scene point (x,y,z mm) at the device's origin (default: the "
                  "scene's centre)");
  cmd->add_option("--view", f.request.view,
                  "openhaptics/dhd: the user stands at the patient's back or front")
      ->capture_default_str();
  if (!viewer) {
    cmd->add_option("--max-missed", f.max_missed_percent,
                    "Deadlines a run may miss, % of its ticks, before it warns (--strict: fails)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 100.0));
    cmd->add_flag("--strict", f.strict,
                  "Exit with status 1 when the loop missed more deadlines than --max-missed "
                  "allows");
  }
  cmd->add_option("--duration", f.request.duration_s,
                  "Seconds to run (0: the script's or recording's length; null: 10 s)")
      ->capture_default_str();
  cmd->add_option("--probe-radius", f.request.probe_radius_mm, "Probe sphere radius, mm")
      ->capture_default_str();
  cmd->add_option("--renderer", f.request.renderer,
                  "proxy (god-object, default) or gao-gibson (the thesis's penalty method)")
      ->capture_default_str();
  cmd->add_option("--stiffness", f.request.stiffness_n_per_mm,
                  "Rendering stiffness, N/mm (0: the device's usable stiffness within the "
                  "Colgate-Brown passivity limit)")
      ->capture_default_str();
  cmd->add_option("--record", f.request.record, "Write every tick to this CSV (replayable)");
  cmd->add_option("--write-scene", f.request.write_scene,
                  "Also write each body's surface to this folder as <name>.obj (mm, world frame)");
  cmd->add_option("--spin-us", f.request.spin_us,
                  "Spin (busy-wait) this long before each deadline instead of sleeping to it, us "
                  "(0: sleep only; steadier periods on virtual machines for some CPU)")
      ->capture_default_str();
  cmd->add_flag("--no-realtime", f.no_realtime, "Do not ask for real-time (SCHED_FIFO) priority");
  cmd->add_flag("--no-floor", f.no_floor,
                "Do not measure the machine's floor beside the loop (a bare periodic thread, like "
                "cyclictest, whose late wake-ups are reported next to the loop's missed "
                "deadlines)");
  add_compliant_stage_flags(cmd, f);
}

void resolve_haptics_run_flags(HapticsRunFlags& f) {
  f.request.realtime_priority = !f.no_realtime;
  f.request.measure_floor = !f.no_floor;
  if (!f.workspace_center.empty()) {
    const auto v = parse_numbers(f.workspace_center, 3, "--workspace-center");
    f.request.workspace_center_mm = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  if (f.request.scene.testdata_dir.empty()) f.request.scene.testdata_dir = testdata_dir();
  f.request.scene.scoliosis = scoliosis_of(f.scoliosis);
  f.request.scene.subject = subject_of(f.body);
  if (f.body.given() && f.request.scene.scene != "spine")
    throw std::invalid_argument(
        "--body-height, --body-mass, --sex and --subject are for --scene spine");
  if (f.body.given()) spine::resolve_subject(data_dir(), f.request.scene.subject);  // in range
  if (!f.chair_file.empty()) {
    if (f.request.posture != "seated")
      throw std::invalid_argument("--chair is for --posture seated");
    f.request.chair.surface = read_chair_surface(f.chair_file);
    f.request.chair.surface_name = f.chair_file;
  }
}

void register_haptics(CLI::App& app) {
  auto* haptics_cmd = app.add_subcommand(
      "haptics", "The 1 kHz haptic loop: touch the spine with a spherical probe");
  haptics_cmd->require_subcommand(1);
  auto a = std::make_shared<HapticsArgs>();
  auto* run = haptics_cmd->add_subcommand(
      "run", "Run the servo loop on a scene with a device (sim: a scripted hand)");
  add_haptics_run_flags(run, a->flags, false);
  add_output_flags(run, a->json, a->quiet);
  run->callback([a] { run_haptics_cli(*a); });

  auto* devices = haptics_cmd->add_subcommand(
      "devices", "List the device backends built in and the device models known");
  struct DevicesArgs {
    bool json = false;
    std::string hd, dhd;
  };
  auto d = std::make_shared<DevicesArgs>();
  devices->add_flag("--json", d->json, "One JSON object on stdout");
  devices->add_option("--openhaptics-lib", d->hd, "OpenHaptics HD library to try (libHD.so)");
  devices->add_option("--dhd-lib", d->dhd, "Force Dimension DHD library to try (libdhd.so)");
  devices->callback([d] {
    if (d->json)
      print_json(haptic_devices_json(d->hd, d->dhd));
    else
      std::cout << haptic_devices_table(d->hd, d->dhd);
  });
}

void register_haptic_plane(CLI::App& study) {
  auto a = std::make_shared<PlaneArgs>();
  auto* cmd = study.add_subcommand(
      "haptic-plane",
      "Thesis figs 4.16-4.19: Gao-Gibson force against intrusion depth for two probe sizes");
  cmd->add_option("--radius", a->request.small_radius_mm,
                  "Small probe radius, mm (the large one's is twice it)")
      ->capture_default_str();
  cmd->add_option("--step", a->request.step_mm, "Depth step, mm")->capture_default_str();
  cmd->add_option("--spacing", a->request.spacing_mm, "Surface sample spacing, mm")
      ->capture_default_str();
  cmd->add_option("--stiffness", a->request.stiffness_eq410_n_per_mm,
                  "Eq 4.10 stiffness, N/mm (eq 4.9's is matched at the small probe's peak)")
      ->capture_default_str();
  cmd->add_flag("--csv", a->csv, "Print the force-depth table as CSV");
  cmd->add_option("--out", a->out, "Also write the CSV to this file");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] { run_plane(*a); });
}

void register_haptic_drag(CLI::App& study) {
  struct DragArgs {
    HapticDragRequest request;
    std::string which;
    bool json = false, quiet = false, no_realtime = false;
  };
  auto a = std::make_shared<DragArgs>();
  auto* cmd = study.add_subcommand(
      "haptic-drag",
      "Thesis 4.5/6.3: a scripted hand drags T1 with the multirate spine and with the "
      "displacement-force database; pose error of each against direct solves, vertebra-pair "
      "motions as CSV");
  cmd->add_option("--case", a->which, "lateral, sagittal or oblique (default: all three)");
  cmd->add_option("--out", a->request.out, "Folder for the recordings and CSVs")->required();
  cmd->add_option("--sample-every", a->request.sample_every_s,
                  "Direct solves this often while hooked, s")
      ->capture_default_str();
  cmd->add_flag("--no-realtime", a->no_realtime, "Do not ask for real-time priority");
  cmd->add_flag("--no-discs{false}", a->request.discs,
                "Skip the 17 offline discs driven by each multirate recording");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->callback([a] {
    if (!a->which.empty()) a->request.cases = {a->which};
    a->request.realtime_priority = !a->no_realtime;
    const bool show = !a->quiet && !a->json && stderr_is_terminal();
    const auto r = run_haptic_drag_study(a->request, data_dir(), [show](const std::string& s) {
      if (show) std::fprintf(stderr, "  %s ...\n", s.c_str());
    });
    if (a->json)
      print_json(haptic_drag_json(r));
    else
      std::cout << haptic_drag_table(r);
  });
}

}  // namespace spinesim::cli
