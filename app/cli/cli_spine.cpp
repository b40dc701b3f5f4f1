// spinesim spine — the vertebra-driven thoracolumbar spine (spine/, thesis 3.3) from the command line.
//
//   spinesim spine solve --force T7:0,0,300
//   spinesim spine solve --force T1:-200,0,0 --fusion L3-L4-L5 --criterion minmax --json
//   spinesim spine solve --force T6:0,-194,0 --at 0,380,700 --no-muscles --csv spine.csv
//
// solve: quasi-static equilibrium under gravity and the given dead loads (spine/equilibrium.hpp):
// the lumbar muscles are recruited by static optimisation (Ipopt; polynomial Σ(F/Fmax)^p or
// min–max) in the reference posture, then Newton finds the posture. Printed: every vertebra's
// displacement, every joint's reaction (joint frame and disc frame), the strongest muscles and
// ligaments, the IAP bushing's wrench, the recruitment's status and the timings; --json gives all
// of it, --csv one row per vertebra and the joint below it.
//
//          loads (N at a point, N·mm couples) on any of T1 … L5
//      T1 ─┐
//          ⋮  17 vertebrae, spherical joints at the F.2 points
//      L5 ─┘
//      sacrum, pelvis: fixed
//
// Units: mm, N, N·mm (N·m in the readable tables), degrees. Frame: x lateral (the body's right is
// −x), y superior, z anterior. Bad input, a non-converged solve included: one line on stderr, exit
// status 1, no file written. A force beyond the 600 N the thesis validated is solved with a
// warning on stderr.
#include "cli_common.hpp"

#include "spinesim/studies/spine_solve.hpp"

#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <numeric>
#include <sstream>

namespace spinesim::cli {
namespace {

struct SpineSolveArgs {
  std::vector<std::string> forces, moments, points;
  std::string fusion, criterion = "polynomial", csv, disc_joints, ligaments = "auto";
  double power = 3;
  double tolerance_nmm = spine::SolveOptions().tolerance;
  int max_iterations = spine::SolveOptions().max_iterations;
  int top = 10;
  bool no_muscles = false, no_trunk_muscles = false, no_gravity = false, json = false,
       rib_cage = false;
  SubjectFlags subject;
  ScoliosisFlags scoliosis;
  ModelInputFlags inputs;
};

void solve(const SpineSolveArgs& a) {
  // 1. Options and loads, checked before any work (nothing is written on bad input).
  spine::SolveOptions options;
  options.warn_above_600n = false;  // warned below, before the solve
  options.recruit = !a.no_muscles;
  if (a.criterion == "polynomial")
    options.recruitment.criterion = spine::Criterion::Polynomial;
  else if (a.criterion == "minmax")
    options.recruitment.criterion = spine::Criterion::MinMax;
  else
    throw std::invalid_argument("--criterion '" + a.criterion + "': use polynomial or minmax");
  if (!std::isfinite(a.power) || a.power < 1)
    throw std::invalid_argument("--power must be a finite number >= 1");
  options.recruitment.power = a.power;
  if (!std::isfinite(a.tolerance_nmm) || a.tolerance_nmm <= 0)
    throw std::invalid_argument("--tolerance must be a finite number > 0 N·mm");
  if (a.max_iterations < 1) throw std::invalid_argument("--max-iterations must be >= 1");
  if (a.top < 0) throw std::invalid_argument("--top must be >= 0");
  options.tolerance = a.tolerance_nmm;
  options.max_iterations = a.max_iterations;
  if (!a.points.empty() && a.points.size() != a.forces.size())
    throw std::invalid_argument("--at: give one point per --force (" +
                                std::to_string(a.forces.size()) + " forces, " +
                                std::to_string(a.points.size()) + " points)");

  std::vector<spine::ExternalLoad> loads;
  std::vector<std::string> warnings;
  for (std::size_t i = 0; i < a.forces.size(); ++i) {
    const auto [vertebra, force] = parse_vertebra_vector(a.forces[i], "--force", "Fx,Fy,Fz");
    spine::ExternalLoad l;
    l.vertebra = vertebra;
    l.force_n = force;
    if (!a.points.empty()) {
      l.has_point = true;
      l.point_mm = Eigen::Vector3d(parse_numbers(a.points[i], 3, "--at"));
    }
    // Refused here, before any warning about it: one line for one mistake.
    if (!(force.norm() <= spine::kMaxForceN))
      throw std::invalid_argument("--force " + a.forces[i] + ": beyond " +
                                  fixed(spine::kMaxForceN, 0) + " N, outside any physical load");
    if (l.has_point && !(l.point_mm.norm() <= spine::kMaxPointMm))
      throw std::invalid_argument("--at " + a.points[i] + ": more than " +
                                  fixed(spine::kMaxPointMm, 0) + " mm from the origin");
    if (force.norm() > kValidatedForceN)
      warnings.push_back("--force " + a.forces[i] + ": |F| = " + fixed(force.norm(), 1) +
                         " N is beyond the " + fixed(kValidatedForceN, 0) +
                         " N the thesis validated; solving anyway");
    loads.push_back(l);
  }
  for (const auto& text : a.moments) {
    const auto [vertebra, moment] = parse_vertebra_vector(text, "--moment", "Mx,My,Mz");
    spine::ExternalLoad l;
    l.vertebra = vertebra;
    l.moment_nmm = moment;
    loads.push_back(l);
  }
  spine::ModelOptions model_options;
  try {
    if (!a.fusion.empty()) model_options.fused_joints = spine::parse_fusion(a.fusion);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--fusion " + a.fusion + ": " + e.what());
  }
  model_options.muscles = !a.no_muscles;
  model_options.trunk_muscles = !a.no_trunk_muscles;
  model_options.gravity = !a.no_gravity;
  model_options.disc_joints = a.disc_joints;
  model_options.ligaments = spine::parse_ligaments(a.ligaments);
  model_options.rib_cage = a.rib_cage;
  model_options.subject = spine::resolve_subject(data_dir(), subject_of(a.subject));
  model_options.scoliosis = scoliosis_of(a.scoliosis);
  apply_model_inputs(a.inputs, model_options);
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");

  // 2. Model and equilibrium (studies/spine_solve.hpp).
  for (const auto& w : warnings) std::cerr << "spinesim: warning: " << w << std::endl;
  const SpineSolveRun run = studies::run_spine_solve(data_dir(), {loads, model_options, options});
  for (const auto& w : run.solution.warnings)
    std::cerr << "spinesim: warning: " << one_line(w) << std::endl;

  // 3. Output.
  if (!a.csv.empty()) write_csv_file(a.csv, spine_solve_csv(run.solution));
  if (a.json)
    print_json(spine_solve_json(run, a.csv));
  else
    print_spine_solve(std::cout, run, a.top, a.csv);
}

}  // namespace

void register_spine(CLI::App& app) {
  auto* spine_cmd = app.add_subcommand(
      "spine", "The vertebra-driven thoracolumbar spine: equilibrium, muscles, joint forces");
  spine_cmd->require_subcommand(1);

  auto a = std::make_shared<SpineSolveArgs>();
  auto* cmd = spine_cmd->add_subcommand(
      "solve", "Quasi-static equilibrium under gravity and loads on any vertebra");
  cmd->add_option("--force", a->forces,
                  "VERTEBRA:Fx,Fy,Fz in N at the vertebra's centre (repeatable), e.g. T7:0,0,300")
      ->allow_extra_args(false);
  cmd->add_option("--moment", a->moments, "VERTEBRA:Mx,My,Mz couple in N·mm (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option(
         "--at", a->points,
         "x,y,z point of the --force with the same position, mm, reference posture (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--fusion", a->fusion, "Fused levels, e.g. L3-L4 or L3-L4-L5 or L3-L4,T12-L1");
  cmd->add_option("--criterion", a->criterion, "Muscle recruitment: polynomial or minmax")
      ->capture_default_str();
  cmd->add_option("--power", a->power, "Power p of the polynomial criterion sum (F/Fmax)^p")
      ->capture_default_str();
  cmd->add_flag("--no-muscles", a->no_muscles, "Passive spine: no muscles");
  cmd->add_flag("--no-trunk-muscles", a->no_trunk_muscles,
                "Lumbar muscles F.8-F.19 only: leave out the restored thoracic erector spinae and "
                "rectus abdominis");
  cmd->add_flag("--no-gravity", a->no_gravity, "No weights (vertebrae, head, arms)");
  cmd->add_option("--disc-joints", a->disc_joints,
                  "Joint springs from each level's disc (a data/spine/disc_joints/ preset such as "
                  "fibre-reinforced, or a file from `spine disc-joints`) in place of the thesis's "
                  "F.4");
  add_ligaments_option(cmd, a->ligaments);
  add_rib_cage_option(cmd, a->rib_cage);
  add_scoliosis_options(cmd, a->scoliosis);
  add_subject_options(cmd, a->subject);
  add_model_input_options(cmd, a->inputs);
  cmd->add_option("--tolerance", a->tolerance_nmm, "Newton tolerance on max |dPi/dtheta|, N·mm")
      ->capture_default_str();
  cmd->add_option("--max-iterations", a->max_iterations, "Newton iterations before giving up")
      ->capture_default_str();
  cmd->add_option("--top", a->top, "Muscles and ligaments listed in the table")
      ->capture_default_str();
  cmd->add_option("--csv", a->csv, "Write one row per vertebra and the joint below it");
  cmd->add_flag("--json", a->json,
                "Print everything as one JSON object on stdout (instead of the tables)");
  cmd->footer(
      "Loads are dead loads (constant direction and size) given in the reference posture. Gravity "
      "acts on the\n"
      "vertebrae (Bruno et al. 2015 masses), the head and neck (on T1) and the arms (on the rib "
      "cage, T6).\n"
      "Muscles: the thesis's lumbar set (tables F.8-F.19) and the LifeMOD trunk muscles it names "
      "without data\n"
      "(thoracic erector spinae, rectus abdominis; data/spine/trunk_muscles.csv). They are "
      "recruited for the\n"
      "lumbar joints T12-L1 ... L5-S1 in the reference posture, then act as\n"
      "springs with short-range stiffness while Newton finds the equilibrium (spine/README.md).\n"
      "Joint reaction: the force the lower side exerts on everything above (compression > 0), in "
      "the lower\n"
      "vertebra's axes (the thesis's Fy axial, Fz AP shear) and in the disc mid-plane; moments in "
      "N·m.\n"
      "Forces beyond 600 N (the thesis's validated range) are solved with a warning. A solve that "
      "does not\n"
      "converge is an error (exit 1, nothing written).");
  cmd->callback([a] { solve(*a); });

  // `spinesim spine database` (thesis 3.5) lives in cli_spine_database.cpp.
  register_spine_database(*spine_cmd);
  register_spine_discs(*spine_cmd);
  register_spine_schedule(*spine_cmd);
  register_spine_disc_joints(*spine_cmd);
}

}  // namespace spinesim::cli
