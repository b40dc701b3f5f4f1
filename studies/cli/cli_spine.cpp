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

#include "spinesim/common/timer.hpp"
#include "model_flags.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/mss_run.hpp"  // write_text_file, require_output_folder
#include "spinesim/studies/spine_studies.hpp"

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

/// The thesis validated its spine for forces up to 600 N (thesis 3.5: 0 … 600 N in 50 N steps).
constexpr double kValidatedForceN = 600.0;

struct SpineSolveArgs {
  std::vector<std::string> forces, moments, points;
  std::string fusion, criterion = "polynomial", csv;
  double power = 3;
  double tolerance_nmm = spine::SolveOptions().tolerance;
  int max_iterations = spine::SolveOptions().max_iterations;
  int top = 10;
  bool no_muscles = false, no_trunk_muscles = false, no_gravity = false, json = false;
};

/// "T7:0,0,300" → vertebra index and three finite numbers; errors name the option.
std::pair<int, Eigen::Vector3d> parse_vertebra_vector(const std::string& text, const std::string& option,
                                                      const std::string& what) {
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument(option + " '" + text + "': expected VERTEBRA:" + what + " (e.g. T7:0,0,300)");
  int vertebra = 0;
  try {
    vertebra = spine::vertebra_index(text.substr(0, colon));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(option + " '" + text + "': " + e.what());
  }
  const Eigen::VectorXd v = parse_numbers(text.substr(colon + 1), 3, option + " " + text.substr(0, colon));
  return {vertebra, Eigen::Vector3d(v)};
}

/// Newlines in a solver diagnostic would break the one-line error contract.
std::string vec3(const Eigen::Vector3d& v, int decimals) {
  return "(" + fixed(v.x(), decimals) + ", " + fixed(v.y(), decimals) + ", " + fixed(v.z(), decimals) + ")";
}

nlohmann::json vec_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

/// Indices of `v` by decreasing value, at most `n`.
std::vector<int> top_indices(const Eigen::VectorXd& v, int n) {
  std::vector<int> idx(std::size_t(v.size()));
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return v(a) > v(b); });
  if (int(idx.size()) > n) idx.resize(std::size_t(n));
  return idx;
}

double value_or_zero(const Eigen::VectorXd& v, std::size_t i) { return Eigen::Index(i) < v.size() ? v(Eigen::Index(i)) : 0.0; }

std::string solve_csv(const spine::SpineSolution& s) {
  std::ostringstream os;
  os << std::setprecision(10)
     << "vertebra,tx_mm,ty_mm,tz_mm,rx_deg,ry_deg,rz_deg,joint_below,axial_n,shear_ap_n,shear_lat_n,disc_axial_n,"
        "disc_shear_n,resultant_n,moment_x_nmm,moment_y_nmm,moment_z_nmm\n";
  for (std::size_t i = 0; i < s.joints.size(); ++i) {
    const auto& j = s.joints[i];
    os << spine::vertebra_names()[i];
    for (int k = 0; k < 6; ++k) os << "," << s.displacement(Eigen::Index(i), k);
    os << "," << j.joint << "," << j.axial_n << "," << j.shear_ap_n << "," << j.shear_lat_n << "," << j.disc_axial_n << ","
       << j.disc_shear_n << "," << j.force_world_n.norm();
    for (int k = 0; k < 3; ++k) os << "," << j.moment_local_nmm(k);
    os << "\n";
  }
  return os.str();
}

void run_spine_solve(const SpineSolveArgs& a) {
  // 1. Options and loads, checked before any work (nothing is written on bad input).
  spine::SolveOptions options;
  options.warn_above_600n = false;  // warned below, before the solve
  options.recruit = !a.no_muscles;
  if (a.criterion == "polynomial") options.recruitment.criterion = spine::Criterion::Polynomial;
  else if (a.criterion == "minmax") options.recruitment.criterion = spine::Criterion::MinMax;
  else throw std::invalid_argument("--criterion '" + a.criterion + "': use polynomial or minmax");
  if (!std::isfinite(a.power) || a.power < 1) throw std::invalid_argument("--power must be a finite number >= 1");
  options.recruitment.power = a.power;
  if (!std::isfinite(a.tolerance_nmm) || a.tolerance_nmm <= 0) throw std::invalid_argument("--tolerance must be a finite number > 0 N·mm");
  if (a.max_iterations < 1) throw std::invalid_argument("--max-iterations must be >= 1");
  if (a.top < 0) throw std::invalid_argument("--top must be >= 0");
  options.tolerance = a.tolerance_nmm;
  options.max_iterations = a.max_iterations;
  if (!a.points.empty() && a.points.size() != a.forces.size())
    throw std::invalid_argument("--at: give one point per --force (" + std::to_string(a.forces.size()) + " forces, " +
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
    if (force.norm() > kValidatedForceN)
      warnings.push_back("--force " + a.forces[i] + ": |F| = " + fixed(force.norm(), 1) + " N is beyond the " +
                         fixed(kValidatedForceN, 0) + " N the thesis validated; solving anyway");
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
  if (!a.csv.empty()) require_output_folder(a.csv, "--csv");

  // 2. Model and equilibrium.
  for (const auto& w : warnings) std::cerr << "spinesim: warning: " << w << std::endl;
  const Timer t0;
  const spine::SpineModel m = spine::load_spine_model(data_dir(), model_options);
  const double model_s = t0.seconds();
  spine::SpineSolution s;
  try {
    s = spine::solve_spine(m, loads, options);
  } catch (const spine::SolveError& e) {
    const std::string what = one_line(e.what());
    throw std::runtime_error(what.find("equilibrium") != std::string::npos ? what
                                                                            : "the spine did not reach equilibrium: " + what);
  }
  const double total_s = t0.seconds();
  for (const auto& w : s.warnings) std::cerr << "spinesim: warning: " << one_line(w) << std::endl;

  // 3. Output.
  if (!a.csv.empty()) write_text_file(a.csv, solve_csv(s));
  const auto& names = spine::vertebra_names();
  const Eigen::VectorXd& recruited = s.recruitment.force_n;
  Eigen::VectorXd max_force(Eigen::Index(m.muscles.size()));
  for (std::size_t i = 0; i < m.muscles.size(); ++i) max_force(Eigen::Index(i)) = m.muscles[i].max_force_n();
  const double max_reserve_nmm = s.recruitment.reserve_nmm.size() ? s.recruitment.reserve_nmm.cwiseAbs().maxCoeff() : 0.0;
  std::string fused;
  for (int j : model_options.fused_joints) fused += (fused.empty() ? "" : ", ") + spine::joint_names()[std::size_t(j)];
  const std::string criterion = a.criterion == "minmax" ? "min-max" : "polynomial, p = " + fixed(a.power, 1);

  if (a.json) {
    nlohmann::json load_list = nlohmann::json::array(), vertebrae = nlohmann::json::array(), joints = nlohmann::json::array(),
                   muscles = nlohmann::json::array(), ligaments = nlohmann::json::array();
    for (const auto& l : loads)
      load_list.push_back({{"vertebra", names[std::size_t(l.vertebra)]},
                           {"force_n", vec_json(l.force_n)},
                           {"moment_nmm", vec_json(l.moment_nmm)},
                           {"point_mm", vec_json(l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm)}});
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto row = s.displacement.row(Eigen::Index(i));
      vertebrae.push_back({{"name", names[i]},
                           {"translation_mm", {row(0), row(1), row(2)}},
                           {"rotation_deg", {row(3), row(4), row(5)}}});
    }
    for (const auto& j : s.joints) joints.push_back(joint_reaction_json(j));
    for (std::size_t i = 0; i < m.muscles.size(); ++i) {
      const auto& mu = m.muscles[i];
      muscles.push_back({{"name", mu.name},
                         {"group", mu.group},
                         {"side", mu.side},
                         {"max_force_n", mu.max_force_n()},
                         {"recruited_force_n", value_or_zero(recruited, i)},
                         {"activation", value_or_zero(s.recruitment.activation, i)},
                         {"tension_n", value_or_zero(s.muscle_force_n, i)}});
    }
    for (std::size_t i = 0; i < m.ligaments.size(); ++i) {
      const auto& li = m.ligaments[i];
      ligaments.push_back({{"name", li.name},
                           {"type", li.type},
                           {"joint", li.joint >= 0 ? spine::joint_names()[std::size_t(li.joint)] : ""},
                           {"force_n", value_or_zero(s.ligament_force_n, i)}});
    }
    const Eigen::Matrix<double, 6, 1>& b = s.bushing_wrench;
    const nlohmann::json j = {
        {"loads", load_list},
        {"options",
         {{"fusion", model_options.fused_joints.empty() ? nlohmann::json::array() : nlohmann::json(fused)},
          {"muscles", !a.no_muscles},
          {"gravity", !a.no_gravity},
          {"criterion", a.criterion},
          {"power", a.power},
          {"tolerance_nmm", options.tolerance},
          {"max_iterations", options.max_iterations}}},
        {"converged", s.converged},
        {"iterations", s.iterations},
        {"gradient_norm_nmm", s.gradient_norm},
        {"stability",
         {{"min_stiffness_nmm_per_rad", s.min_stiffness_nmm_per_rad},
          {"stable", s.min_stiffness_nmm_per_rad > 0},
          {"softest_mode", s.softest_mode},
          {"sagittal_solve", s.sagittal_solve}}},
        {"vertebrae", vertebrae},
        {"joints", joints},
        {"muscles", muscles},
        {"ligaments", ligaments},
        {"bushing", {{"enabled", m.has_bushing}, {"force_n", {b(0), b(1), b(2)}}, {"moment_nmm", {b(3), b(4), b(5)}}}},
        {"recruitment",
         {{"enabled", options.recruit},
          {"success", s.recruitment.success},
          {"status", s.recruitment.status},
          {"iterations", s.recruitment.iterations},
          {"objective", s.recruitment.objective},
          {"max_constraint_violation_nmm", s.recruitment.max_constraint_violation_nmm},
          {"max_reserve_nmm", max_reserve_nmm},
          {"reserve_nmm", to_json(s.recruitment.reserve_nmm)},
          {"seconds", s.recruitment.seconds}}},
        {"warnings", s.warnings},
        {"seconds", {{"model", model_s}, {"recruitment", s.seconds_recruitment}, {"equilibrium", s.seconds_equilibrium}, {"total", total_s}}},
        {"csv", a.csv.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.csv)},
        {"units",
         {{"frame", "x lateral (body's right -x), y superior, z anterior"},
          {"translation_mm", "vertebra F.1 centre, world axes, mm"},
          {"rotation_deg", "rotation vector, world axes, deg"},
          {"joints", "force the lower side exerts on everything above: world N, N·mm about the moved joint point; "
                     "axial/shear in the lower vertebra's axes (compression > 0); disc_* in the disc mid-plane; "
                     "moment_local x flexion+, y torsion, z lateral bending"}}}};
    print_json(j);
    return;
  }

  std::cout << "Spine equilibrium (thesis 3.3): x lateral (body's right -x), y superior, z anterior\n"
            << "  model: " << (a.no_gravity ? "no gravity" : "gravity") << ", "
            << (a.no_muscles ? "no muscles" : "muscles recruited (" + criterion + ")") << ", " << m.ligaments.size()
            << " ligaments" << (m.has_bushing ? ", IAP bushing" : "") << "; fusion: " << (fused.empty() ? "none" : fused) << "\n";
  for (std::size_t i = 0; i < loads.size(); ++i) {
    const auto& l = loads[i];
    std::cout << "  load " << i + 1 << ": " << names[std::size_t(l.vertebra)];
    if (l.force_n.squaredNorm() > 0)
      std::cout << " force " << vec3(l.force_n, 1) << " N at "
                << vec3(l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm, 1) << " mm";
    if (l.moment_nmm.squaredNorm() > 0) std::cout << " couple " << vec3(l.moment_nmm, 1) << " N·mm";
    std::cout << "\n";
  }
  if (loads.empty()) std::cout << "  no external load (gravity only)\n";
  std::cout << "  converged in " << s.iterations << " Newton iterations, max |dPi/dtheta| " << std::setprecision(2)
            << std::scientific << s.gradient_norm << std::defaultfloat << " N·mm\n";
  std::cout << "  tangent stiffness: smallest eigenvalue " << std::setprecision(4) << s.min_stiffness_nmm_per_rad / 1000
            << " N·m/rad (" << (s.min_stiffness_nmm_per_rad > 0 ? "stable" : "NOT stable") << "), softest mode "
            << s.softest_mode << "\n\n";

  TextTable v({"vertebra", "tx (mm)", "ty (mm)", "tz (mm)", "rx (deg)", "ry (deg)", "rz (deg)"});
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::vector<std::string> row{names[i]};
    for (int k = 0; k < 6; ++k) row.push_back(fixed(s.displacement(Eigen::Index(i), k), k < 3 ? 3 : 4));
    v.add(row);
  }
  std::cout << "Vertebra displacement (centre translation, rotation vector; world axes)\n";
  v.print(std::cout, false);

  TextTable jt({"joint", "axial (N)", "shear AP (N)", "shear lat (N)", "disc axial (N)", "disc shear (N)", "|F| (N)",
                "Mx flex+ (N·m)", "My torsion (N·m)", "Mz lat (N·m)"});
  for (const auto& j : s.joints)
    jt.add({j.joint + (std::find(model_options.fused_joints.begin(), model_options.fused_joints.end(),
                                 spine::joint_index(j.joint)) != model_options.fused_joints.end() ? " (fused)" : ""),
            fixed(j.axial_n, 1), fixed(j.shear_ap_n, 1), fixed(j.shear_lat_n, 1), fixed(j.disc_axial_n, 1),
            fixed(j.disc_shear_n, 1), fixed(j.force_world_n.norm(), 1), fixed(j.moment_local_nmm.x() * 1e-3, 3),
            fixed(j.moment_local_nmm.y() * 1e-3, 3), fixed(j.moment_local_nmm.z() * 1e-3, 3)});
  std::cout << "\nJoint reactions (lower side on everything above; joint frame = lower vertebra's axes, compression > 0)\n";
  jt.print(std::cout, false);

  if (!a.no_muscles && !m.muscles.empty() && recruited.size() == Eigen::Index(m.muscles.size())) {
    int active = 0;
    for (Eigen::Index i = 0; i < recruited.size(); ++i) active += recruited(i) > 1e-3 * max_force(i);
    TextTable mt({"muscle", "group", "side", "recruited F (N)", "F max (N)", "activation", "tension (N)"}, 3);
    for (int i : top_indices(recruited, a.top)) {
      const auto& mu = m.muscles[std::size_t(i)];
      mt.add({mu.name, mu.group, mu.side, fixed(recruited(i), 1), fixed(mu.max_force_n(), 1),
              fixed(value_or_zero(s.recruitment.activation, std::size_t(i)), 3),
              fixed(value_or_zero(s.muscle_force_n, std::size_t(i)), 1)});
    }
    std::cout << "\nMuscles: " << active << " of " << m.muscles.size() << " active (F > 0.1 % of F max); the "
              << std::min<std::size_t>(std::size_t(a.top), m.muscles.size()) << " strongest (tension: at the equilibrium posture)\n";
    mt.print(std::cout, false);
  }
  if (!m.ligaments.empty() && s.ligament_force_n.size() == Eigen::Index(m.ligaments.size())) {
    int taut = 0;
    for (Eigen::Index i = 0; i < s.ligament_force_n.size(); ++i) taut += s.ligament_force_n(i) > 0;
    TextTable lt({"ligament", "type", "joint", "force (N)"}, 3);
    for (int i : top_indices(s.ligament_force_n, a.top)) {
      if (s.ligament_force_n(i) <= 0) break;
      const auto& li = m.ligaments[std::size_t(i)];
      lt.add({li.name, li.type, li.joint >= 0 ? spine::joint_names()[std::size_t(li.joint)] : "-", fixed(s.ligament_force_n(i), 2)});
    }
    std::cout << "\nLigaments: " << taut << " of " << m.ligaments.size() << " in tension; the strongest\n";
    lt.print(std::cout, false);
  }
  if (m.has_bushing) {
    const auto& b = s.bushing_wrench;
    std::cout << "\nIAP bushing on the rib cage (" << names[std::size_t(m.ribs_body)] << "): force "
              << vec3(Eigen::Vector3d(b(0), b(1), b(2)), 1) << " N, moment "
              << vec3(Eigen::Vector3d(b(3), b(4), b(5)) * 1e-3, 3) << " N·m\n";
  }
  if (options.recruit)
    std::cout << "Recruitment: " << (s.recruitment.success ? "success" : "FAILED") << " (" << s.recruitment.status << ", "
              << s.recruitment.iterations << " Ipopt iterations), objective " << std::setprecision(4)
              << s.recruitment.objective << ", max equilibrium violation " << fixed(s.recruitment.max_constraint_violation_nmm, 3)
              << " N·mm, largest reserve moment " << fixed(max_reserve_nmm * 1e-3, 3) << " N·m\n";
  std::cout << "Time: model " << fixed(model_s * 1e3, 1) << " ms, recruitment " << fixed(s.seconds_recruitment * 1e3, 1)
            << " ms, equilibrium " << fixed(s.seconds_equilibrium * 1e3, 1) << " ms, total " << fixed(total_s * 1e3, 1) << " ms"
            << (a.csv.empty() ? "" : "; wrote " + a.csv) << "\n";
}

}  // namespace

void register_spine(CLI::App& app) {
  auto* spine_cmd = app.add_subcommand("spine", "The vertebra-driven thoracolumbar spine: equilibrium, muscles, joint forces");
  spine_cmd->require_subcommand(1);

  auto a = std::make_shared<SpineSolveArgs>();
  auto* cmd = spine_cmd->add_subcommand("solve", "Quasi-static equilibrium under gravity and loads on any vertebra");
  cmd->add_option("--force", a->forces, "VERTEBRA:Fx,Fy,Fz in N at the vertebra's centre (repeatable), e.g. T7:0,0,300")
      ->allow_extra_args(false);
  cmd->add_option("--moment", a->moments, "VERTEBRA:Mx,My,Mz couple in N·mm (repeatable)")->allow_extra_args(false);
  cmd->add_option("--at", a->points, "x,y,z point of the --force with the same position, mm, reference posture (repeatable)")
      ->allow_extra_args(false);
  cmd->add_option("--fusion", a->fusion, "Fused levels, e.g. L3-L4 or L3-L4-L5 or L3-L4,T12-L1");
  cmd->add_option("--criterion", a->criterion, "Muscle recruitment: polynomial or minmax")->capture_default_str();
  cmd->add_option("--power", a->power, "Power p of the polynomial criterion sum (F/Fmax)^p")->capture_default_str();
  cmd->add_flag("--no-muscles", a->no_muscles, "Passive spine: no muscles");
  cmd->add_flag("--no-trunk-muscles", a->no_trunk_muscles,
                "Lumbar muscles F.8-F.19 only: leave out the restored thoracic erector spinae and rectus abdominis");
  cmd->add_flag("--no-gravity", a->no_gravity, "No weights (vertebrae, head, arms)");
  cmd->add_option("--tolerance", a->tolerance_nmm, "Newton tolerance on max |dPi/dtheta|, N·mm")->capture_default_str();
  cmd->add_option("--max-iterations", a->max_iterations, "Newton iterations before giving up")->capture_default_str();
  cmd->add_option("--top", a->top, "Muscles and ligaments listed in the table")->capture_default_str();
  cmd->add_option("--csv", a->csv, "Write one row per vertebra and the joint below it");
  cmd->add_flag("--json", a->json, "Print everything as one JSON object on stdout (instead of the tables)");
  cmd->footer(
      "Loads are dead loads (constant direction and size) given in the reference posture. Gravity acts on the\n"
      "vertebrae (Bruno et al. 2015 masses), the head and neck (on T1) and the arms (on the rib cage, T6).\n"
      "Muscles: the thesis's lumbar set (tables F.8-F.19) and the LifeMOD trunk muscles it names without data\n"
      "(thoracic erector spinae, rectus abdominis; data/spine/trunk_muscles.csv). They are recruited for the\n"
      "lumbar joints T12-L1 ... L5-S1 in the reference posture, then act as\n"
      "springs with short-range stiffness while Newton finds the equilibrium (spine/README.md).\n"
      "Joint reaction: the force the lower side exerts on everything above (compression > 0), in the lower\n"
      "vertebra's axes (the thesis's Fy axial, Fz AP shear) and in the disc mid-plane; moments in N·m.\n"
      "Forces beyond 600 N (the thesis's validated range) are solved with a warning. A solve that does not\n"
      "converge is an error (exit 1, nothing written).");
  cmd->callback([a] { run_spine_solve(*a); });

  // `spinesim spine database` (thesis 3.5) lives in cli_spine_database.cpp.
  register_spine_database(*spine_cmd);
}

}  // namespace spinesim::cli
