// spinesim study — the thesis's studies as runnable programs that write what they measured.
//
//   spinesim study probe [--out study-out] [--radius 3] [--depth 2] [--speed 20] [--no-radial | --volume-term]
//   spinesim study drive [--out study-out] [--materials real-disc,annulus-nucleus,rubber,polyethylene]
//   spinesim study materials [--level L4-L5] [--cell-size 2] [--materials …] [--csv materials.csv]
//   spinesim study validation [--csv validation.csv] [--json]
//   spinesim study fusion [--force 300] [--csv fusion.csv] [--json]
//   spinesim study trends [--force 300] [--csv trends.csv] [--json]
//
// probe — thesis 5.3, test 1 (fig. 5.8): a rigid sphere pressed into the outer wall of a disc
//   whose endplates are both fixed, held, withdrawn, then at a second site while the first
//   recovers; the disc volume is tracked (the thesis claimed it is preserved, never measured).
// drive — thesis 5.3, test 2 (fig. 5.9): an L2-L3 disc, L3 (inferior) fixed, L2 (superior)
//   driven by a motion schedule, once per material preset; the reaction shows how stiff each
//   material is (the thesis: polyethylene stiffest, the real disc softest).
// materials — thesis fig. 5.9 with a reference: per material preset, the linear FEM, the
//   untuned thesis MSS and the MSS calibrated to that FEM, side by side (materials_study.hpp);
//   tables on stdout, --csv, --json; no --out folder.
// probe and drive: implicit Euler, dt 1 ms (the thesis's 1 kHz), a VTU time series (.pvd,
// frames every --frame-every steps), a CSV per run and a JSON summary in --out. A run whose step
// diverges stops there: its files hold the finite states up to that step, "diverged": true is
// in the JSON, and the program exits 1 after the other runs.
// validation, fusion, trends — the spine (spine_studies.hpp): thesis 3.4's two validation cases
//   beside their targets, 6.1's fusion comparison and 6.3-6.4's relative vertebra motions under a
//   force on T1, each thesis statement reported as MATCH or DIFFERS; tables, --csv, --json.
//
// Adding a study: write its Args struct (with a StudyCommon), run_<name>() and a register
// function below, and add one line to register_study() at the end of this file.
#include "cli_common.hpp"

#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/studies/drive_study.hpp"
#include "spinesim/studies/probe_study.hpp"

#include "spinesim/mss/quantities.hpp"

#include "model_flags.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/studies/body_study.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/materials_study.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/rib_cage_study.hpp"
#include "spinesim/studies/scoliosis_study.hpp"
#include "spinesim/studies/spine_solve.hpp"
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/studies/standing_gap_study.hpp"

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mss/boundary.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/simulator.hpp"
#include "spinesim/mss/solver.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <unordered_map>

namespace spinesim::cli {
namespace {
namespace fs = std::filesystem;

// --- shared by every study ---------------------------------------------------------------------

/// Options every study has: where to write, which disc, how to step, which model terms.
struct StudyCommon {
  std::string out = "study-out", mesh_path, level, integrator = "implicit";
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  double dt_s = 1e-3;
  int frame_every = 10, newton_iterations = 1;
  bool frozen = false, json = false, quiet = false;
  ModelFlags model;
};

void add_common_options(CLI::App* cmd, StudyCommon& c) {
  cmd->add_option("--out", c.out, "Output folder (created)")->capture_default_str();
  cmd->add_option("--mesh", c.mesh_path, "Disc mesh VTU (default: mesh --level in-process)");
  cmd->add_option("--level", c.level, "Disc level meshed when no --mesh is given")
      ->capture_default_str();
  cmd->add_option("--cell-size", c.cell_size_mm, "Mesh cell size, mm")->capture_default_str();
  cmd->add_option("--dt", c.dt_s, "Time step, s")->capture_default_str();
  cmd->add_option("--integrator", c.integrator, "implicit, symplectic or explicit")
      ->capture_default_str();
  cmd->add_option("--newton", c.newton_iterations, "Implicit: max Newton iterations per step")
      ->capture_default_str();
  cmd->add_flag("--frozen", c.frozen,
                "Implicit: keep the rest-stiffness factorisation (one solve per step)");
  cmd->add_option("--frame-every", c.frame_every, "A VTU frame every K steps")
      ->capture_default_str();
  add_model_flags(cmd, c.model);
  add_output_flags(cmd, c.json, c.quiet, "the JSON summary");
}

/// Checks the shared options (before any work) and returns the dynamics options.
mss::DynamicsOptions check_common(const StudyCommon& c) {
  if (!std::isfinite(c.dt_s) || c.dt_s <= 0)
    throw std::invalid_argument("--dt must be a finite number > 0 s");
  if (c.frame_every < 1) throw std::invalid_argument("--frame-every must be >= 1");
  if (c.newton_iterations < 1) throw std::invalid_argument("--newton must be >= 1");
  if (c.mesh_path.empty() && (!std::isfinite(c.cell_size_mm) || c.cell_size_mm <= 0))
    throw std::invalid_argument("--cell-size must be a finite number > 0 mm");
  model_options(c.model);  // validates --damping
  mss::DynamicsOptions o;
  o.integrator = parse_integrator(c.integrator);
  o.dt_s = c.dt_s;
  o.newton_iterations = c.newton_iterations;
  o.matrix_update = c.frozen ? mss::MatrixUpdate::frozen : mss::MatrixUpdate::every_iteration;
  return o;
}

/// The study's disc: read --mesh, or mesh --level in-process (as `demo` does).
mesh::TetMesh study_mesh(const StudyCommon& c, Progress& progress) {
  if (!c.mesh_path.empty()) {
    progress.begin("reading " + c.mesh_path);
    mesh::TetMesh m = mesh::read_tet_mesh(c.mesh_path);
    mesh::require_endplate_labels(m);
    progress.end(std::to_string(m.num_tets()) + " tets");
    return m;
  }
  const auto dims = mesh::disc_dimensions(c.level, data_dir());
  mesh::MeshOptions opt;
  opt.cell_size_mm = c.cell_size_mm;
  progress.begin("meshing the " + dims.level + " disc");
  mesh::TetMesh m = mesh::mesh_disc_level(dims.level, opt, data_dir());
  progress.end(std::to_string(m.num_tets()) + " tets");
  return m;
}

// --- study probe -------------------------------------------------------------------------------

struct ProbeArgs {
  StudyCommon common;
  // Defaults as ProbeStudyRequest (studies/probe_study.hpp).
  double radius_mm = 3.0, depth_mm = 2.0, speed_mm_s = 20.0, hold_s = 0.1, rest_s = 0.2,
         stiffness_n_per_mm = 0.0;
  std::string material = "real-disc", sites = "anterior,left";
};

/// The stepping options of the studies' flags (checked by check_common).
SteppedStudyOptions stepping(const StudyCommon& c, const mss::DynamicsOptions& dyn) {
  SteppedStudyOptions o;
  o.out = c.out;
  o.dynamics = dyn;
  o.integrator_name = c.integrator;
  o.frame_every = c.frame_every;
  o.model = model_options(c.model);
  o.model_variant = model_variant(c.model);
  return o;
}

void run_probe(ProbeArgs a) {
  // 1. Options, checked before any work.
  StudyCommon& c = a.common;
  ProbeStudyRequest rq;
  rq.stepping = stepping(c, check_common(c));
  rq.radius_mm = a.radius_mm, rq.depth_mm = a.depth_mm, rq.speed_mm_s = a.speed_mm_s;
  rq.hold_s = a.hold_s, rq.rest_s = a.rest_s, rq.stiffness_n_per_mm = a.stiffness_n_per_mm;
  rq.sites = split_list(a.sites);
  check(rq);
  const auto materials = mesh::load_material(a.material, data_dir());

  // 2. Disc, then the study (studies/probe_study.hpp).
  Progress progress(4, c.quiet || c.json);
  const mesh::TetMesh m = study_mesh(c, progress);
  const ProbeStudyResult r = run_probe_study(m, materials, rq, progress.hooks());
  if (c.json)
    print_json(r.summary);
  else
    print_probe_study(std::cout, m, materials.name, r);
  if (r.stats.diverged)
    throw std::runtime_error("probe study diverged at step " +
                             std::to_string(r.stats.steps_done + 1) + ": " + r.stats.message);
}

// --- study drive -------------------------------------------------------------------------------

struct DriveArgs {
  StudyCommon common;
  std::string materials = "real-disc,annulus-nucleus,rubber,polyethylene";
  double compression_mm = 0.5, flexion_deg = 3.0, time_scale = 1.0;
};

void run_drive(DriveArgs a) {
  // 1. Options, checked before any work.
  StudyCommon& c = a.common;
  DriveStudyRequest rq;
  rq.stepping = stepping(c, check_common(c));
  rq.compression_mm = a.compression_mm, rq.flexion_deg = a.flexion_deg;
  rq.time_scale = a.time_scale;
  for (const auto& name : split_list(a.materials))
    rq.materials.push_back(mesh::load_material(name, data_dir()));
  check(rq);

  // 2. Disc, then one run per material (studies/drive_study.hpp).
  Progress progress(1 + int(rq.materials.size()), c.quiet || c.json);
  const mesh::TetMesh m = study_mesh(c, progress);
  const DriveStudyResult r = run_drive_study(m, rq, progress.hooks());
  if (c.json)
    print_json(r.summary);
  else
    print_drive_study(std::cout, m, r);
  if (!r.diverged().empty()) throw std::runtime_error("drive study diverged for: " + r.diverged());
}

// --- study materials ---------------------------------------------------------------------------

struct MaterialsArgs {
  std::string level = "L4-L5",
              materials = "real-disc,annulus-nucleus,fibre-reinforced,rubber,polyethylene", csv,
              terms = "thesis+volume";
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  bool json = false, quiet = false;
};

/// Throws std::invalid_argument unless `path` can be created (its folder exists and is writable).
void require_writable(const std::string& path, const std::string& option) {
  require_output_folder(path, option);
  const fs::path dir =
      fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  if (::access(dir.c_str(), W_OK) != 0)
    throw std::invalid_argument(option + " " + path + ": folder " + dir.string() +
                                " is not writable");
}

void run_materials(const MaterialsArgs& a) {
  // 1. Options, checked before any work (nothing is written on bad input).
  if (!std::isfinite(a.cell_size_mm) || a.cell_size_mm <= 0)
    throw std::invalid_argument("--cell-size must be a finite number > 0 mm");
  mesh::disc_dimensions(a.level, data_dir());  // throws for an unknown level
  MaterialsStudyOptions options;
  options.terms = parse_term_set(a.terms);
  std::vector<mesh::RegionMaterials> materials;
  for (const auto& name : split_list(a.materials))
    materials.push_back(mesh::load_material(name, data_dir()));
  if (materials.empty()) throw std::invalid_argument("--materials: give at least one material");
  if (!a.csv.empty()) require_writable(a.csv, "--csv");
  const Timer t_start;

  // 2. One mesh for every material, then the study (studies/materials_study.hpp).
  Progress progress(1 + kStagesPerMaterial * int(materials.size()), a.quiet || a.json);
  StudyCommon c;
  c.level = a.level;
  c.cell_size_mm = a.cell_size_mm;
  const mesh::TetMesh m = study_mesh(c, progress);
  if (!a.json) print_materials_header(std::cout, m, a.cell_size_mm, options, materials);
  MaterialsStudy study = run_materials_study(m, materials, options, progress.hooks());
  study.level = a.level;
  study.cell_size_mm = a.cell_size_mm;

  // 3. Tables, CSV, summary.
  if (!a.csv.empty()) write_csv_file(a.csv, materials_csv(study.results));
  if (a.json) {
    print_json(materials_study_json(m, study, a.csv));
  } else {
    print_materials(std::cout, study.results, options.fem_order, false);
    std::cout << "Total " << std::setprecision(3) << t_start.seconds() << " s"
              << (a.csv.empty() ? "" : "; wrote " + a.csv) << "\n";
  }
  if (!study.failed().empty())
    throw std::runtime_error("calibration failed for: " + study.failed());
}

// --- registration ------------------------------------------------------------------------------

void register_probe(CLI::App& study) {
  auto a = std::make_shared<ProbeArgs>();
  a->common.level = "L4-L5";
  auto* cmd = study.add_subcommand(
      "probe", "Thesis 5.3 test 1: a rigid sphere pressed into the disc wall, volume tracked");
  add_common_options(cmd, a->common);
  cmd->add_option("--material", a->material, "Preset or JSON file")->capture_default_str();
  cmd->add_option("--radius", a->radius_mm, "Probe radius, mm")->capture_default_str();
  cmd->add_option("--depth", a->depth_mm, "Indentation depth into the undeformed surface, mm")
      ->capture_default_str();
  cmd->add_option("--speed", a->speed_mm_s, "Press and withdraw speed, mm/s")
      ->capture_default_str();
  cmd->add_option("--hold", a->hold_s, "Hold at full depth, s")->capture_default_str();
  cmd->add_option("--rest", a->rest_s, "Probe away after each site (recovery), s")
      ->capture_default_str();
  cmd->add_option("--probe-stiffness", a->stiffness_n_per_mm,
                  "Penalty per node, N/mm (0: the solver's default, 100 x the mean edge stiffness "
                  "from the rest Hessian)")
      ->capture_default_str();
  cmd->add_option("--sites", a->sites, "Sites in order: anterior, posterior, left, right")
      ->capture_default_str();
  cmd->footer("Writes OUT/probe.pvd (+ OUT/probe/ frames), OUT/probe.csv and OUT/probe.json.");
  cmd->callback([a] { run_probe(*a); });
}

void register_drive(CLI::App& study) {
  auto a = std::make_shared<DriveArgs>();
  a->common.level = "L2-L3";
  auto* cmd = study.add_subcommand(
      "drive", "Thesis 5.3 test 2: L2-L3 disc, L3 fixed, L2 driven, per material");
  add_common_options(cmd, a->common);
  cmd->add_option("--materials", a->materials, "Comma-separated presets or JSON files")
      ->capture_default_str();
  cmd->add_option("--compression", a->compression_mm, "Axial compression of the schedule, mm")
      ->capture_default_str();
  cmd->add_option("--flexion", a->flexion_deg, "Flexion of the schedule, degrees")
      ->capture_default_str();
  cmd->add_option("--time-scale", a->time_scale, "Multiply the schedule's times (1.2 s at 1)")
      ->capture_default_str();
  cmd->footer(
      "Schedule (disc frame, linear in between): 0-0.2 s compress; 0.3-0.5 s flex; 0.6-0.8 s "
      "unflex;\n"
      "0.9-1.1 s release; hold 0.1 s between. Writes OUT/drive-<material>.pvd (+ frames), "
      "OUT/drive-<material>.csv\n"
      "(time, plate motion mm/deg, reaction N and N·mm in the disc frame, volume) and "
      "OUT/drive.json.");
  cmd->callback([a] { run_drive(*a); });
}

void register_materials(CLI::App& study) {
  auto a = std::make_shared<MaterialsArgs>();
  auto* cmd = study.add_subcommand("materials",
                                   "Thesis fig. 5.9 with a reference: per material, FEM vs untuned "
                                   "vs tuned MSS under the same load");
  cmd->add_option("--level", a->level, "Disc level, meshed in-process")->capture_default_str();
  cmd->add_option("--cell-size", a->cell_size_mm, "Mesh cell size, mm")->capture_default_str();
  cmd->add_option("--materials", a->materials, "Comma-separated presets or JSON files")
      ->capture_default_str();
  cmd->add_option("--terms", a->terms, "What the calibration tunes: thesis, thesis+volume, all")
      ->capture_default_str();
  cmd->add_option("--csv", a->csv,
                  "Write a CSV, one row per material x model (fem, untuned, tuned)");
  add_output_flags(cmd, a->json, a->quiet, "the JSON summary (instead of the tables)");
  cmd->footer(
      "Protocol: one mesh of --level for every material; inferior endplate fixed, superior "
      "endplate a rigid\n"
      "plate about the mean of its vertices. Per material:\n"
      "  1. FEM P2, linear: the 6x6 plate stiffness and the compression case (F_y = -500 N in the "
      "disc\n"
      "     frame, the thesis's fig. 5.9 load);\n"
      "  2. Ipopt calibrates the MSS stiffness scales (--terms, per region) to that FEM on "
      "compression,\n"
      "     shear-ap, flexion and torsion, linearised (as `spinesim calibrate --no-check`);\n"
      "  3. the untuned MSS (thesis network: main + radial + torsion springs, Van Gelder "
      "constants) and\n"
      "     the tuned MSS, nonlinear static under the same wrench.\n"
      "Reported per model, disc frame (x lateral, y axial, z anterior): axial stiffness K6_yy "
      "(N/mm) and\n"
      "the 6x6 diagonal (N/mm, N·mm/deg), linear at rest; under the compression: the superior "
      "plate's u_y\n"
      "(mm), max |u| (mm), the volume change (MSS: signed tet volumes; FEM: the P1 volume of the "
      "mesh with\n"
      "its vertices moved by the FEM displacement) and the nodal displacement error vs the FEM.\n"
      "Output: tables on stdout (or --json), --csv FILE. Exit 1 if a calibration fails (tables "
      "still shown).");
  cmd->callback([a] { run_materials(*a); });
}

// --- study validation | fusion | trends (the spine; spine_studies.hpp) ------------------------

struct SpineStudyArgs {
  double force_n = 300;
  std::string csv, disc_joints, ligaments = "auto";
  bool json = false, quiet = false, no_trunk_muscles = false, rib_cage = false;
  SubjectFlags subject;
  spine::ModelOptions model() const {
    spine::ModelOptions o;
    o.rib_cage = rib_cage;
    o.trunk_muscles = !no_trunk_muscles;
    o.ligaments = spine::parse_ligaments(ligaments);
    o.subject = subject_of(subject);
    o.disc_joints = disc_joints;
    return o;
  }
};

/// Lines under the title when the study runs on the lumbar muscles only or on disc joints.
void print_muscle_set(const SpineStudyArgs& a) {
  if (a.no_trunk_muscles)
    std::cout << "Muscles: F.8-F.19 only (--no-trunk-muscles: no thoracic erector spinae, no "
                 "rectus abdominis)\n\n";
  const spine::ModelOptions o = a.model();
  if (spine::has_ligaments(o) && o.disc_joints.empty())
    std::cout << "Ligaments: F.6/F.7 on top of F.4 (--ligaments on: the thesis's model, which "
                 "counts them twice)\n\n";
  if (!spine::has_ligaments(o) && !o.disc_joints.empty())
    std::cout << "Ligaments: none (--ligaments off) on the disc joints\n\n";
  if (a.rib_cage) std::cout << "Rib cage: on (--rib-cage; data/spine/rib_cage.json)\n\n";
  if (a.subject.given())
    std::cout << "Body: " << subject_text(spine::resolve_subject(data_dir(), o.subject))
              << (a.subject.named.empty()
                      ? " (--height/--mass/--sex; the reference body is male, 1.778 m, 70 kg)"
                      : " (--subject " + a.subject.named + ")")
              << "\n\n";
  if (!a.disc_joints.empty())
    std::cout << "Joint springs: the discs of " << a.disc_joints
              << " (--disc-joints) in place of the thesis's F.4\n\n";
}

void add_spine_study_options(CLI::App* cmd, SpineStudyArgs& a, bool with_force) {
  if (with_force)
    cmd->add_option("--force", a.force_n, "Force on the T1 centre, N")->capture_default_str();
  cmd->add_option("--csv", a.csv, "Write the study's CSV");
  cmd->add_flag("--json", a.json, "Print the JSON summary on stdout (instead of the tables)");
  cmd->add_flag("--no-trunk-muscles", a.no_trunk_muscles,
                "Lumbar muscles F.8-F.19 only: leave out the restored thoracic erector spinae and "
                "rectus abdominis");
  cmd->add_flag("--quiet", a.quiet, "No progress on stderr");
  add_ligaments_option(cmd, a.ligaments);
  add_rib_cage_option(cmd, a.rib_cage);
  add_subject_options(cmd, a.subject);
  cmd->add_option("--disc-joints", a.disc_joints,
                  "Joint springs from each level's disc (a data/spine/disc_joints/ preset such as "
                  "fibre-reinforced, or a file from `spine disc-joints`) in place of F.4");
}

/// Checks shared by the spine studies before any work; returns the progress hooks.
StageHooks spine_study_hooks(const SpineStudyArgs& a, Progress& progress) {
  if (!std::isfinite(a.force_n) || a.force_n <= 0)
    throw std::invalid_argument("--force must be a finite number > 0 N");
  if (a.force_n > 600)
    std::cerr << "spinesim: warning: --force " << a.force_n
              << " N is beyond the 600 N the thesis validated; solving anyway" << std::endl;
  spine::resolve_subject(data_dir(), subject_of(a.subject));  // a body out of range: refused now
  if (!a.csv.empty()) require_writable(a.csv, "--csv");
  StageHooks hooks;
  hooks.begin = [&progress](const std::string& what) { progress.begin(what); };
  hooks.end = [&progress](const std::string& detail) { progress.end(detail); };
  return hooks;
}

/// Writes the CSV (--csv), then prints the JSON summary (--json) or the title, the muscle set and the table.
template <class Study>
void emit_spine_study(const SpineStudyArgs& a, const Study& s, const char* title,
                      std::string (*to_csv)(const Study&), nlohmann::json (*to_json)(const Study&),
                      void (*print)(std::ostream&, const Study&, bool), bool markdown = false) {
  if (!a.csv.empty() && to_csv) write_csv_file(a.csv, to_csv(s));
  if (a.json) {
    nlohmann::json j = to_json(s);
    j["csv"] = a.csv.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.csv);
    print_json(j);
    return;
  }
  std::cout << title << "\n\n";
  print_muscle_set(a);
  print(std::cout, s, markdown);
  std::cout << "Total " << fixed(s.seconds, 2) << " s" << (a.csv.empty() ? "" : "; wrote " + a.csv)
            << "\n";
}

void run_validation(const SpineStudyArgs& a) {
  Progress progress(kValidationStages, a.quiet || a.json);
  const ValidationStudy s =
      run_validation_study(data_dir(), a.model(), spine_study_hooks(a, progress));
  emit_spine_study(
      a, s,
      "Spine validation (thesis 3.4): McGill & Norman 1987 at L5-S1, Wilke et al. 2001 at L4-L5",
      validation_csv, validation_json, print_validation);
}

void run_fusion(const SpineStudyArgs& a) {
  Progress progress(kFusionStages, a.quiet || a.json);
  const FusionStudy s =
      run_fusion_study(data_dir(), a.force_n, a.model(), spine_study_hooks(a, progress));
  emit_spine_study(a, s, "Spinal fusion vs the normal spine (thesis 6.1)", fusion_csv, fusion_json,
                   print_fusion);
}

void run_trends(const SpineStudyArgs& a) {
  Progress progress(kTrendsStages, a.quiet || a.json);
  const TrendsStudy s =
      run_trends_study(data_dir(), a.force_n, a.model(), spine_study_hooks(a, progress));
  emit_spine_study(a, s,
                   "Relative motion of adjacent vertebrae under a force on T1 (thesis 6.3-6.4)",
                   trends_csv, trends_json, print_trends);
}

void register_validation(CLI::App& study) {
  auto a = std::make_shared<SpineStudyArgs>();
  auto* cmd = study.add_subcommand(
      "validation",
      "Thesis 3.4: L5-S1 forces at a 238 N·m extension moment, L4-L5 force holding a crate");
  add_spine_study_options(cmd, *a, false);
  cmd->footer(
      "(a) McGill & Norman 1987: a +z force on the T7 centre raised until the net external moment "
      "about the\n"
      "    L5-S1 joint point (T7 force and every weight above, in the equilibrium posture) is 238 "
      "N·m; L5-S1\n"
      "    axial and shear force (joint and disc frames) against 3929-4688 N and <= 650 N.\n"
      "(b) Wilke et al. 2001: 19.8 kg crate 600 mm in front of the chest, arms forward; L4-L5 "
      "axial force\n"
      "    against 3240 N +- 15 %. Targets: data/spine/spine_model.json \"validation\". Nothing is "
      "tuned.\n"
      "Output: table (or --json with each case's forces beside its targets), --csv FILE. A missed "
      "target is\n"
      "reported (exit 0); a failed solve is an error (exit 1).");
  cmd->callback([a] { run_validation(*a); });
}

void register_fusion(CLI::App& study) {
  auto a = std::make_shared<SpineStudyArgs>();
  auto* cmd = study.add_subcommand(
      "fusion", "Thesis 6.1: normal spine vs fusion at L3-L4, L4-L5, L3-L4-L5 under forces on T1");
  add_spine_study_options(cmd, *a, true);
  cmd->footer(
      "The same forward (+z), backward (-z) and lateral (-x) force on the T1 centre, per model: T1 "
      "motion (the\n"
      "force's effect, minus the model's gravity-only equilibrium; mm, deg) and the L2-L3 and "
      "L5-S1 joint\n"
      "forces (totals, joint frame; N). The thesis's findings are checked: MATCH or DIFFERS, not "
      "forced.");
  cmd->callback([a] { run_fusion(*a); });
}

void register_trends(CLI::App& study) {
  auto a = std::make_shared<SpineStudyArgs>();
  auto* cmd = study.add_subcommand("trends",
                                   "Thesis 6.3-6.4: relative motion of adjacent vertebrae under "
                                   "forces on T1, vs the thesis's trends");
  add_spine_study_options(cmd, *a, true);
  cmd->footer(
      "Lateral (-x), forward (+z) and backward (-z) force on the T1 centre. Per pair T1-T2 ... "
      "L4-L5: relative\n"
      "translation of the centres (upper minus lower, world axes, mm) and the joint rotation "
      "(deg), each minus its\n"
      "gravity-only value. Each trend the thesis states is printed as MATCH or DIFFERS with our "
      "numbers.");
  cmd->callback([a] { run_trends(*a); });
}
}  // namespace

// --- study rib-cage (rib_cage_study.hpp) ----------------------------------------------------

void register_rib_cage(CLI::App& study) {
  struct Args {
    SpineStudyArgs spine;
    double moment_nm = 2;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = study.add_subcommand(
      "rib-cage",
      "The rib cage's stiffening of the thoracic spine beside cadaver tests that removed it");
  cmd->add_option("--moment", a->moment_nm, "Pure moment on T1, N·m (Liebsch et al. 2017: 2)")
      ->capture_default_str();
  cmd->add_flag("--json", a->spine.json,
                "Print the JSON summary on stdout (instead of the tables)");
  cmd->add_flag("--quiet", a->spine.quiet, "No progress on stderr");
  add_ligaments_option(cmd, a->spine.ligaments);
  add_subject_options(cmd, a->spine.subject);
  cmd->footer(
      "The thoracic spine T1-T12 alone (T12 held; no gravity, muscles or IAP), a couple of "
      "+-M about each axis\n"
      "on T1: T1's range of motion without the cage, with the ribs on their heads only (the "
      "costal cartilage\n"
      "removed), with the whole cage and with its springs' stiffness changed; how much the range "
      "grows when the\n"
      "cage is removed, beside Liebsch et al. 2017 and Mannen et al. 2018. Then standing and a "
      "300 N forward\n"
      "force on T1 with and without the cage (the full model). Nothing is tuned.");
  cmd->callback([a] {
    if (!std::isfinite(a->moment_nm) || a->moment_nm < 0.1 || a->moment_nm > 20)
      throw std::invalid_argument("--moment must lie within 0.1 … 20 N·m");
    Progress progress(8, a->spine.quiet || a->spine.json);
    const RibCageStudy s = run_rib_cage_study(data_dir(), a->moment_nm, a->spine.model(),
                                              spine_study_hooks(a->spine, progress));
    if (a->spine.json) {
      print_json(rib_cage_study_json(s));
      return;
    }
    std::cout << "The rib cage and the thoracic spine's stiffness (in vitro: Liebsch et al. "
                 "2017, Mannen et al. 2018)\n\n";
    print_rib_cage_study(std::cout, s, false);
  });
}

// --- study scoliosis (scoliosis_study.hpp) --------------------------------------------------

void register_scoliosis(CLI::App& study) {
  auto a = std::make_shared<SpineStudyArgs>();
  auto* cmd =
      study.add_subcommand("scoliosis",
                           "Disc loads on the concave and convex sides of scoliotic spines beside "
                           "published findings");
  cmd->add_flag("--json", a->json, "Print the JSON summary on stdout (instead of the tables)");
  cmd->add_flag("--quiet", a->quiet, "No progress on stderr");
  add_ligaments_option(cmd, a->ligaments);
  add_subject_options(cmd, a->subject);
  cmd->footer(
      "Thoracic (T5-T11, apex T8, right), thoracolumbar (T10-L2, apex T12, right) and lumbar "
      "(T12-L4, apex L2,\n"
      "left) curves at Cobb 20, 40 and 60 deg, each resting in its curve (spine/README.md), "
      "stand under gravity\n"
      "with the muscles recruited; each disc of the curve is read as a beam on its elliptic "
      "section. Findings:\n"
      "Meir et al. 2007 (stress peaks in the concave annulus; 0.25 MPa without muscle load), "
      "Modi et al. 2008\n"
      "(wedging greatest at the apex). A curve the model cannot pose is listed with the reason.");
  cmd->callback([a] {
    Progress progress(3, a->quiet || a->json);
    const ScoliosisStudy s =
        run_scoliosis_study(data_dir(), a->model(), spine_study_hooks(*a, progress));
    if (a->json) {
      print_json(scoliosis_study_json(s));
      return;
    }
    std::cout << "Scoliotic spines: disc loads on the concave and convex sides (Meir et al. "
                 "2007, Modi et al. 2008)\n\n";
    print_scoliosis_study(std::cout, s);
  });
}

// --- study bodies (body_study.hpp) ------------------------------------------------------------

/// --json, --markdown, --quiet, --ligaments and --rib-cage of the studies over many spines.
void add_model_and_output_flags(CLI::App* cmd, SpineStudyArgs& a, bool& markdown) {
  cmd->add_flag("--json", a.json, "Print the JSON summary on stdout (instead of the tables)");
  cmd->add_flag("--markdown", markdown, "Print the tables as Markdown");
  cmd->add_flag("--quiet", a.quiet, "No progress on stderr");
  add_ligaments_option(cmd, a.ligaments);
  add_rib_cage_option(cmd, a.rib_cage);
}

void register_bodies(CLI::App& study) {
  struct Args {
    SpineStudyArgs spine;
    std::vector<std::string> bodies;
    bool markdown = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = study.add_subcommand(
      "bodies",
      "Validation, fusion, trends and the in-vivo postures for a 5th-percentile woman, the "
      "thesis's man and a 95th-percentile man");
  cmd->add_option("--force", a->spine.force_n, "Force on the T1 centre (fusion, trends), N")
      ->capture_default_str();
  cmd->add_option("--bodies", a->bodies,
                  "Named bodies to compare, e.g. p5-female,reference (default: every one in "
                  "data/spine/spine_model.json anthropometry.bodies)")
      ->delimiter(',');
  cmd->add_option("--csv", a->spine.csv, "Write the comparison as CSV (a row per quantity)");
  add_model_and_output_flags(cmd, a->spine, a->markdown);
  cmd->footer(
      "Every body is scaled from the reference body as --height/--mass/--sex would scale it "
      "(spine/README.md);\n"
      "the loads stay the thesis's. The validation windows are one male subject's each: for the "
      "other bodies\n"
      "they are shown for scale. A few seconds per body.");
  cmd->callback([a] {
    const std::size_t n =
        a->bodies.empty() ? spine::named_bodies(data_dir()).size() : a->bodies.size();
    Progress progress(kBodyStudyStagesPerBody * int(n), a->spine.quiet || a->spine.json);
    const BodyStudy s = run_body_study(data_dir(), a->spine.force_n, a->spine.model(), a->bodies,
                                       spine_study_hooks(a->spine, progress));
    emit_spine_study(a->spine, s,
                     "The spine studies for sourced bodies (data/spine/spine_model.json "
                     "anthropometry.bodies)",
                     body_study_csv, body_study_json, print_body_study, a->markdown);
  });
}

// --- study standing-gap (standing_gap_study.hpp) ----------------------------------------------

void register_standing_gap(CLI::App& study) {
  struct Args {
    SpineStudyArgs spine;
    double prestress_mpa = 0.10;
    bool markdown = false;
  };
  auto a = std::make_shared<Args>();
  auto* cmd = study.add_subcommand(
      "standing-gap",
      "Why standing L4-L5 is too light: the disc's swelling pressure, co-contraction and resting "
      "muscle tone, each measured against the in-vivo postures");
  cmd->add_option("--swelling-pressure", a->prestress_mpa,
                  "The unloaded disc's pressure, MPa (Wilke et al. 1999, lying prone: 0.10)")
      ->capture_default_str();
  add_model_and_output_flags(cmd, a->spine, a->markdown);
  add_subject_options(cmd, a->spine.subject);
  cmd->footer(
      "Each case solves standing, sitting without a backrest, leaning back in a chair (110 deg) "
      "and holding\n"
      "Wilke's crate, and reads L4-L5 beside Wilke et al. 1999/2001 (as `study "
      "seating-validation`). The last two\n"
      "cases find, by bisection, the co-contraction or tone that closes standing on top of the "
      "swelling pressure,\n"
      "and show what that does to the other rows. docs/seating.md discusses the result.");
  cmd->callback([a] {
    Progress progress(kStandingGapStages, a->spine.quiet || a->spine.json);
    const StandingGapStudy s = run_standing_gap_study(
        data_dir(), a->spine.model(), a->prestress_mpa, spine_study_hooks(a->spine, progress));
    emit_spine_study<StandingGapStudy>(
        a->spine, s,
        "The standing gap: mechanisms that raise the standing disc load, each measured (in vivo: "
        "Wilke et al. 1999, 2001)",
        nullptr, standing_gap_study_json, print_standing_gap_study, a->markdown);
  });
}

void register_study(CLI::App& app) {
  auto* study = app.add_subcommand(
      "study",
      "The thesis's studies (5.3 functional tests, material comparison), as VTU series, CSV, JSON");
  study->require_subcommand(1);
  register_probe(*study);
  register_drive(*study);
  register_materials(*study);
  register_validation(*study);
  register_fusion(*study);
  register_trends(*study);
  register_rib_cage(*study);
  register_scoliosis(*study);
  register_bodies(*study);
  register_standing_gap(*study);
  register_haptic_plane(*study);
  register_haptic_drag(*study);
  register_disc_validation(*study);
  register_disc_identify(*study);
  register_mss_fibres(*study);
  register_cohort_level(*study);
  register_seating(*study);
}

}  // namespace spinesim::cli
