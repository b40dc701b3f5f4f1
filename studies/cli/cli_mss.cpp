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
#include "spinesim/studies/calibration_report.hpp"

#include "model_flags.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/fem_report.hpp"
#include "spinesim/studies/mss_run.hpp"

#include "spinesim/calibration/tuned_set.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/solver.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;

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

/// The model's options and material: from the flags, or from a tuned file (--params), which
/// fixes the terms and scales and must match the mesh and material (calibration_report.hpp).
struct ModelChoice {
  mss::MssOptions options;
  mesh::RegionMaterials materials;
  std::string constants = "untuned Van Gelder";
  std::string variant;
};

ModelChoice choose_model(const ModelFlags& flags, const std::string& params,
                         const std::string& material, bool material_given) {
  ModelChoice c;
  if (params.empty()) {
    c.options = model_options(flags);
    c.materials = mesh::load_material(material, data_dir());
    c.variant = model_variant(flags);
    return c;
  }
  const mss::MssOptions defaults;
  if (flags.no_radial || flags.no_torsion || flags.volume_term || flags.disc_volume_term ||
      flags.volume_factor != defaults.volume_factor ||
      flags.disc_volume_factor != defaults.disc_volume_factor)
    throw std::invalid_argument(
        "--params fixes the model's terms: drop "
        "--no-radial/--no-torsion/--volume-term/--disc-volume-term and their factors");
  const calibration::TunedDisc tuned = calibration::read_tuned_for_mesh(params, nullptr);
  c.options = tuned.mss_options();
  const mss::MssOptions damping = model_options(flags);  // --damping still applies
  c.options.damping_n_s_per_mm = damping.damping_n_s_per_mm;
  // Not the preset of that name: the file may have been fitted with a material JSON file.
  c.materials = material_given ? mesh::load_material(material, data_dir()) : tuned.materials();
  c.constants = "tuned (" + params + ")";
  c.variant = "tuned " + std::string(c.options.volume_term ? "thesis+volume" : "thesis") +
              (c.options.disc_volume_term ? "+disc-volume" : "") +
              (tuned.per_spring() ? ", per-spring" : "");
  return c;
}

/// The MSS for `m`: with a tuned file, only after it was checked against the mesh and material
/// (a per-spring file: the very mesh it was fitted on).
mss::MssModel build_model(const mesh::TetMesh& m, const ModelChoice& c, const std::string& params,
                          bool quiet) {
  if (params.empty()) return mss::MssModel(m, c.materials, c.options);
  const calibration::TunedDisc tuned = calibration::read_tuned_for_mesh(params, &m);
  mss::MssModel model = tuned_model(tuned, m, c.materials, quiet);
  if (c.options.damping_n_s_per_mm >= 0) {
    mss::MssOptions o = model.options();
    o.damping_n_s_per_mm = c.options.damping_n_s_per_mm;
    return mss::MssModel(m, c.materials, o);
  }
  return model;
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

/// --out checked (a .vtu, or a .pvd series for a dynamic run, in an existing folder); returns
/// whether it is a series.
bool check_output(const MssArgs& a) {
  if (a.out.empty()) return false;
  const bool series = fs::path(a.out).extension() == ".pvd";
  if (fs::path(a.out).extension() != ".vtu" && !series)
    throw std::invalid_argument("--out " + a.out +
                                ": give a .vtu file (or a .pvd time series for a dynamic run)");
  if (series && !a.dynamic)
    throw std::invalid_argument("--out " + a.out +
                                ": a .pvd time series needs a dynamic run (--dt/--steps)");
  require_output_folder(a.out, "--out");
  return series;
}

void run_mss(const MssArgs& a) {
  // 1. Parse and check every option before doing any work: bad input fails fast, writes nothing.
  if (a.mesh_path.empty()) throw std::invalid_argument("--mesh is required");
  const int loads = int(!a.motion.empty()) + int(!a.wrench.empty()) + int(!a.load_case.empty());
  if (loads > 1) throw std::invalid_argument("give at most one of --motion, --wrench and --case");
  if (a.static_run && a.dynamic)
    throw std::invalid_argument("give --static or --dt/--steps/--integrator, not both");
  MssRunRequest rq;
  PlateLoad& load = rq.load;
  if (!a.motion.empty())
    load.value =
        motion_deg_to_rad(parse_numbers(a.motion, 6, "--motion tx,ty,tz,rx,ry,rz (mm, deg)"));
  if (!a.wrench.empty()) {
    load.is_wrench = true;
    load.value = parse_numbers(a.wrench, 6, "--wrench Fx,Fy,Fz,Mx,My,Mz (N, N·mm)");
  }
  const fem::LoadCase* named = a.load_case.empty() ? nullptr : &fem::load_case(a.load_case);
  const Eigen::VectorXd center =
      a.center.empty() ? Eigen::VectorXd() : parse_numbers(a.center, 3, "--center x,y,z (mm)");
  rq.dynamic = a.dynamic;
  rq.dynamics.integrator = check_stepping(a);
  rq.dynamics.dt_s = a.dt_s;
  rq.dynamics.newton_iterations = a.newton_iterations;
  rq.dynamics.matrix_update =
      a.frozen ? mss::MatrixUpdate::frozen : mss::MatrixUpdate::every_iteration;
  rq.integrator_name = a.integrator;
  rq.steps = a.steps;
  rq.frame_every = a.frame_every;
  const ModelChoice choice =
      choose_model(a.model, a.params, a.material, a.material_option->count() > 0);
  const bool series = check_output(a);
  const auto& materials = choice.materials;

  // 2. Mesh and model.
  Progress progress(3 + int(!a.out.empty()), a.quiet || a.json);
  progress.begin("reading " + a.mesh_path);
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  mesh::require_endplate_labels(m);
  const double read_s = progress.end(std::to_string(m.num_tets()) + " tets");
  load.center =
      center.size() == 3 ? Eigen::Vector3d(center) : fem::DiscFem::default_plate_center(m);
  if (named) {
    load.is_wrench = true;
    load.value = fem::global_wrench(*named, m.frame);
  }
  progress.begin("building the mass-spring model");
  const mss::MssModel model = build_model(m, choice, a.params, a.quiet || a.json);
  const double build_s = progress.end(std::to_string(model.num_edge_springs()) + " edge springs");

  // 3. Solve: static equilibrium, or steps in time (studies/mss_run.hpp).
  std::unique_ptr<VtuSeries> frames = series ? std::make_unique<VtuSeries>(a.out) : nullptr;
  const MssRunResult r = run_mss_load(model, rq, frames.get(), progress.hooks());
  nlohmann::json j = mss_run_json(r);
  j["timings"]["read_s"] = read_s;
  j["timings"]["build_s"] = build_s;
  j.update({{"mesh", a.mesh_path},
            {"nodes", m.num_vertices()},
            {"tets", m.num_tets()},
            {"material", materials.name},
            {"plate_center", to_json(Eigen::VectorXd(load.center))},
            {"load", load.is_wrench ? "wrench" : "motion"},
            {"mss_constants", choice.constants}});
  j.update(mss_model_json(model, materials));
  if (!a.params.empty()) j["params"] = a.params;
  if (named) j["case"] = named->name;
  if (!r.failed && r.inverted_tets > 0)
    std::cerr << "spinesim: warning: " << r.inverted_tets
              << " tetrahedra are inside out at the result: the load is beyond what the spring "
                 "network holds (try --volume-term or --disc-volume-term)\n";

  // 4. Output files, only for a run that succeeded: no NaN, no half series.
  if (r.failed && frames) frames->discard();
  if (!r.failed && !a.out.empty()) {
    progress.begin("writing " + a.out);
    if (frames) {
      frames->finish();
      j["frames"] = frames->num_frames();
    } else {
      const mss::StateFields f = mss::state_fields(model, r.x_mm);
      mesh::write_vtu(a.out, m, f.point, f.cell);
    }
    progress.end();
    j["out"] = a.out;
  }

  // 5. Report; a failed run still prints its summary, then exits 1 with the reason.
  if (a.json)
    print_json(j);
  else
    print_mss_run(std::cout, model, a.mesh_path, materials.name,
                  a.params.empty() ? model_variant(a.model) : "tuned (" + a.params + ")", r);
  if (r.failed) throw std::runtime_error(one_line(r.failure));
}

// --- mss compare -------------------------------------------------------------------------------

struct CompareArgs {
  std::string mesh_path, material = "real-disc", cases = "all", csv, params;
  CLI::Option* material_option = nullptr;
  double load_scale = 1.0;
  int order = 2;
  bool json = false, quiet = false;
  ModelFlags model;
};

void run_compare(const CompareArgs& a) {
  // 1. Options.
  const auto cases = fem::parse_load_cases(a.cases);
  const ModelChoice choice =
      choose_model(a.model, a.params, a.material, a.material_option->count() > 0);
  if (!std::isfinite(a.load_scale) || a.load_scale <= 0)
    throw std::invalid_argument("--load-scale must be a finite number > 0");
  if (a.order != 1 && a.order != 2) throw std::invalid_argument("--order must be 1 or 2");
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");
  const auto& materials = choice.materials;

  // 2. Mesh, FEM reference and MSS on the same mesh.
  Progress progress(4, a.quiet || a.json);
  progress.begin("reading " + a.mesh_path);
  const mesh::TetMesh m = mesh::read_tet_mesh(a.mesh_path);
  mesh::require_endplate_labels(m);
  progress.end(std::to_string(m.num_tets()) + " tets");
  progress.begin(
      "building the mass-spring model");  // first: a tuned file that does not apply is refused here
  const mss::MssModel model = build_model(m, choice, a.params, a.quiet || a.json);
  progress.end();
  progress.begin("FEM P" + std::to_string(a.order) + " assembly and factorisation");
  const fem::DiscFem solver(m, materials, a.order, fem::DiscFem::default_plate_center(m));
  progress.end(std::to_string(solver.num_dofs()) + " DOF");

  // 3. The protocol (mss_report.hpp).
  progress.begin("comparing " + std::to_string(cases.size()) + " load cases");
  MssFemComparison cmp = calibration::compare_mss_fem(solver, model, cases, materials.name,
                                                      mss::StaticOptions(), a.load_scale);
  cmp.constants = choice.constants;
  progress.end();

  if (!a.csv.empty()) write_text_file(a.csv, comparison_csv(cmp));
  nlohmann::json j = comparison_json(cmp);
  j["mesh"] = a.mesh_path;
  j["model_variant"] = choice.variant;
  if (!a.params.empty()) j["params"] = a.params;
  if (!a.csv.empty()) j["csv"] = a.csv;
  if (a.json) {
    print_json(j);
    return;
  }
  std::cout << "MSS (" << choice.constants << ", " << choice.variant << ") vs FEM P" << a.order
            << " on " << a.mesh_path << " (" << m.num_vertices() << " nodes, " << m.num_tets()
            << " tets), material " << materials.name
            << (a.load_scale != 1.0 ? ", loads x " + std::to_string(a.load_scale) : std::string())
            << "\n\n";
  print_comparison(std::cout, cmp, false);
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
