// spinesim mss — the thesis's tetrahedral mass-spring disc (ch. 5.2) under a rigid-plate load,
// static or in time, and its comparison with the FEM reference.
//
//   spinesim mss --mesh disc.vtu --case compression --json
//   spinesim mss --mesh disc.vtu --motion 0,-0.5,0,0,0,0 --dt 1e-3 --steps 200 --out run.pvd
//   spinesim mss compare --mesh disc.vtu --cases compression,flexion --csv compare.csv
//
// Boundary (same as `fem`): inferior endplate (surface 1) fixed; superior endplate (surface 2)
// a rigid plate moved by --motion (mm, degrees, exact rigid pose about --center) or loaded by
// --wrench / --case (N, N·mm about --center, plate DOF solved for).
//
//         wrench / motion
//      ====[ plate ]====   superior endplate, rigid
//      |    disc MSS   |
//      =================   inferior endplate, fixed
//
// Static (default): Newton equilibrium. Dynamic (--dt/--steps/--integrator): the load is ramped
// linearly over the first 10 % of the steps (at least one step) and then held, so the plate
// never jumps (a jump of the prescribed pose in one step would give the endplate nodes a
// velocity of Δx/dt); K_d ambient damping (5.11). A step that diverges is rejected: the run stops,
// prints why, says `"diverged": true` in its JSON, writes no file and exits non-zero.
#include "cli_common.hpp"
#include "model_flags.hpp"

#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/mss_verbs.hpp"

#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mss/simulator.hpp"

#include <cmath>
#include <iostream>
#include <memory>

namespace spinesim::cli {
namespace {

struct MssArgs {
  std::string mesh_path, material = "real-disc", params, motion, wrench, load_case, center, out;
  CLI::Option* material_option = nullptr;
  std::string integrator = "implicit";
  double dt_s = 1e-3;
  int steps = 0, frame_every = 0, newton_iterations = 1;
  bool static_run = false, frozen = false, json = false, quiet = false;
  ModelFlags model;
  bool dynamic = false;  ///< set from which options were given
};

/// The model request of the flags: untuned (the flags' terms), or a tuned file (--params), which
/// fixes the terms and scales (calibration/protocol.hpp) and so refuses the term flags.
MssModelRequest model_request(const ModelFlags& flags, const std::string& params,
                              const std::string& material, bool material_given) {
  MssModelRequest rq;
  rq.options = model_options(flags);
  rq.variant = model_variant(flags);
  rq.params = params;
  rq.material = material;
  rq.material_given = material_given;
  const mss::MssOptions defaults;
  if (!params.empty() && (flags.no_radial || flags.no_torsion || flags.volume_term ||
                          flags.disc_volume_term || flags.volume_factor != defaults.volume_factor ||
                          flags.disc_volume_factor != defaults.disc_volume_factor))
    throw std::invalid_argument(
        "--params fixes the model's terms: drop "
        "--no-radial/--no-torsion/--volume-term/--disc-volume-term and their factors");
  return rq;
}

/// The stepping options of a dynamic run, checked; the integrator (implicit for a static run).
mss::Integrator check_stepping(const MssArgs& a) {
  if (!a.dynamic) return mss::Integrator::implicit_euler;
  const mss::Integrator integrator = parse_integrator(a.integrator);
  if (!std::isfinite(a.dt_s) || a.dt_s <= 0)
    throw std::invalid_argument("--dt must be a finite number > 0 s");
  if (a.steps < 1) throw std::invalid_argument("a dynamic run needs --steps N with N >= 1");
  if (a.frame_every < 0) throw std::invalid_argument("--frame-every must be >= 0");
  if (a.newton_iterations < 1) throw std::invalid_argument("--newton must be >= 1");
  return integrator;
}

void run_mss(const MssArgs& a) {
  // 1. Flags into the request (studies/mss_verbs.hpp), every one checked before any work.
  const int loads = int(!a.motion.empty()) + int(!a.wrench.empty()) + int(!a.load_case.empty());
  if (loads > 1) throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  if (loads == 0)
    throw std::invalid_argument(
        "give a load: --motion, --wrench or --case (with none the disc stays at rest)");
  if (a.static_run && a.dynamic)
    throw std::invalid_argument("give --static or --dt/--steps/--integrator, not both");
  MssFileRunRequest rq;
  rq.mesh_path = a.mesh_path;
  PlateLoad& load = rq.run.load;
  if (!a.motion.empty())
    load.value =
        motion_deg_to_rad(parse_numbers(a.motion, 6, "--motion tx,ty,tz,rx,ry,rz (mm, deg)"));
  if (!a.wrench.empty()) {
    load.is_wrench = true;
    load.value = parse_numbers(a.wrench, 6, "--wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm)");
  }
  if (!a.load_case.empty()) rq.load_case = &fem::load_case(a.load_case);
  if (!a.center.empty())
    rq.center = Eigen::Vector3d(parse_numbers(a.center, 3, "--center x,y,z (mm)"));
  rq.run.dynamic = a.dynamic;
  rq.run.dynamics.integrator = check_stepping(a);
  rq.run.dynamics.dt_s = a.dt_s;
  rq.run.dynamics.newton_iterations = a.newton_iterations;
  rq.run.dynamics.matrix_update =
      a.frozen ? mss::MatrixUpdate::frozen : mss::MatrixUpdate::every_iteration;
  rq.run.integrator_name = a.integrator;
  rq.run.steps = a.steps;
  rq.run.frame_every = a.frame_every;
  rq.model = model_request(a.model, a.params, a.material, a.material_option->count() > 0);
  rq.out = a.out;
  rq.quiet = a.quiet || a.json;

  // 2. The driver; a failed run still prints its summary, then exits 1 with the reason.
  Progress progress(mss_file_run_stages(rq), a.quiet || a.json);
  const MssFileRunResult r = run_mss_file(rq, data_dir(), progress.hooks());
  if (!r.warning.empty()) std::cerr << "spinesim: warning: " << r.warning << "\n";
  if (a.json)
    print_json(r.json);
  else
    print_mss_run(std::cout, *r.model, a.mesh_path, r.choice.materials.name,
                  a.params.empty() ? model_variant(a.model) : "tuned (" + a.params + ")", r.run);
  if (r.run.failed) throw std::runtime_error(one_line(r.run.failure));
}

struct CompareArgs {
  std::string mesh_path, material = "real-disc", cases = "all", csv, params;
  CLI::Option* material_option = nullptr;
  double load_scale = 1.0;
  int order = 2;
  bool json = false, quiet = false;
  ModelFlags model;
};

void run_compare(const CompareArgs& a) {
  MssCompareRequest rq;
  rq.mesh_path = a.mesh_path;
  rq.cases = fem::parse_load_cases(a.cases);
  rq.model = model_request(a.model, a.params, a.material, a.material_option->count() > 0);
  rq.load_scale = a.load_scale;
  rq.order = a.order;
  rq.csv = a.csv;
  rq.quiet = a.quiet || a.json;
  Progress progress(4, a.quiet || a.json);
  const MssCompareResult r = run_mss_compare(rq, data_dir(), progress.hooks());
  if (a.json)
    print_json(r.json);
  else
    print_mss_compare(std::cout, rq, r);
}

constexpr const char* kCompareProtocol =
    R"(Protocol (same mesh, each named case's wrench w on the superior plate, inferior fixed):
  (a) wrench-loaded, FEM (vertex displacements) vs MSS static:
      displacement_error = ||u_mss - u_fem|| / ||u_fem|| over all vertices;
      plate_motion_error = RMS over plate nodes of |rigid displacement(q_mss - q_fem)|
                           / RMS |rigid displacement(q_fem)|.
  (b) motion-loaded: the MSS plate moved by the FEM's plate motion; reaction wrench compared,
      moments divided by the plate's RMS radius rho:
      reaction_error = |(dF, dM/rho)| / |(F_fem, M_fem/rho)|, and its force and moment parts
      over the same denominator.
  (c) 6x6 plate stiffness diagonal, MSS (rest Hessian condensed onto the plate) / FEM.
MSS constants: the untuned Van Gelder ones (the baseline calibration must beat), or a tuned file
from `spinesim calibrate` (--params; refused for another material or disc level, and a per-spring
file on any mesh but the one it was fitted on).
--load-scale multiplies every case's wrench: the FEM is linear, so small loads show the linear
regime the calibration fits; the standard loads (7.5 N·m moments) also show the MSS's
geometric nonlinearity.)";

}  // namespace

void register_mss(CLI::App& app) {
  auto a = std::make_shared<MssArgs>();
  auto* cmd = app.add_subcommand(
      "mss", "Tetrahedral mass-spring disc (thesis ch. 5): static or dynamic, rigid-plate load");
  cmd->require_subcommand(0, 1);
  cmd->add_option("--mesh", a->mesh_path,
                  "Disc mesh (VTU with `surface` endplate labels); required");
  a->material_option =
      cmd->add_option(
             "--material", a->material,
             "Preset (real-disc, annulus-nucleus, fibre-reinforced, rubber, polyethylene) or JSON "
             "file")
          ->capture_default_str();
  cmd->add_option("--params", a->params,
                  "Tuned disc from `spinesim calibrate` (sets terms, scales and, unless given, the "
                  "material); or a "
                  "tuned set such as data/tuned_discs.json (the mesh's level is used)");
  add_plate_load_options(cmd, a->motion, a->wrench, a->load_case, a->center);
  cmd->add_flag("--static", a->static_run, "Static equilibrium (the default)");
  auto* dt = cmd->add_option("--dt", a->dt_s, "Time step, s (dynamic run)")->capture_default_str();
  auto* steps = cmd->add_option("--steps", a->steps, "Number of time steps (dynamic run)");
  auto* integ = cmd->add_option("--integrator", a->integrator,
                                "implicit, symplectic or explicit (thesis 5.20-5.21)")
                    ->capture_default_str();
  cmd->add_option("--newton", a->newton_iterations,
                  "Implicit: max Newton iterations per step (1 = Baraff-Witkin)")
      ->capture_default_str();
  cmd->add_flag("--frozen", a->frozen,
                "Implicit: keep the rest-stiffness factorisation (one solve per step)");
  cmd->add_option("--frame-every", a->frame_every,
                  "Dynamic .pvd output: a frame every K steps (0: about 100 frames)");
  add_model_flags(cmd, a->model);
  cmd->add_option("--out", a->out,
                  "Write the result: .vtu (final state) or .pvd (time series of a dynamic run)");
  add_output_flags(cmd, a->json, a->quiet);
  cmd->footer(
      "Dynamic runs ramp the load linearly over the first 10 % of the steps, then hold it. A "
      "diverging run\n"
      "exits 1 with the reason, \"diverged\": true in its JSON and no output file.");

  auto c = std::make_shared<CompareArgs>();
  auto* cmp = cmd->add_subcommand(
      "compare",
      "MSS (untuned, or tuned with --params) vs FEM on the same mesh for the named load cases");
  cmp->add_option("--mesh", c->mesh_path, "Disc mesh (VTU with `surface` endplate labels)")
      ->required();
  c->material_option =
      cmp->add_option("--material", c->material, "Preset or JSON file")->capture_default_str();
  cmp->add_option(
      "--params", c->params,
      "Tuned disc from `spinesim calibrate` instead of the untuned constants (or a tuned set: the "
      "mesh's level)");
  cmp->add_option("--load-scale", c->load_scale, "Multiply every case's wrench by this factor")
      ->capture_default_str();
  cmp->add_option("--cases", c->cases, "Comma-separated load cases, or all")->capture_default_str();
  cmp->add_option("--order", c->order, "FEM element order: 1 (P1) or 2 (P2)")
      ->capture_default_str();
  add_model_flags(cmp, c->model);
  cmp->add_option("--csv", c->csv, "Also write one CSV row per case");
  add_output_flags(cmp, c->json, c->quiet);
  cmp->footer(kCompareProtocol);
  cmp->callback([c] { run_compare(*c); });

  // CLI11 runs the parent's callback after the sub-command's: skip it for `mss compare`.
  cmd->callback([a, cmp, dt, steps, integ] {
    if (cmp->parsed()) return;
    a->dynamic = dt->count() + steps->count() + integ->count() > 0;
    run_mss(*a);
  });
}

}  // namespace spinesim::cli
