#include "spinesim/studies/spine_solve.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <iomanip>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

namespace {

/// "(x, y, z)" with `decimals` digits.
std::string vec3(const Eigen::Vector3d& v, int decimals) {
  return "(" + fixed(v.x(), decimals) + ", " + fixed(v.y(), decimals) + ", " +
         fixed(v.z(), decimals) + ")";
}

/// Indices of `v` by decreasing value, at most `n`.
std::vector<int> top_indices(const Eigen::VectorXd& v, int n) {
  std::vector<int> idx(std::size_t(v.size()));
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return v(a) > v(b); });
  if (int(idx.size()) > n) idx.resize(std::size_t(n));
  return idx;
}

double value_or_zero(const Eigen::VectorXd& v, std::size_t i) {
  return Eigen::Index(i) < v.size() ? v(Eigen::Index(i)) : 0.0;
}

}  // namespace

std::string spine_solve_csv(const spine::SpineSolution& s) {
  std::ostringstream os;
  os << std::setprecision(10)
     << "vertebra,tx_mm,ty_mm,tz_mm,rx_deg,ry_deg,rz_deg,joint_below,axial_n,shear_ap_n,shear_lat_"
        "n,disc_axial_n,"
        "disc_shear_n,resultant_n,moment_x_nmm,moment_y_nmm,moment_z_nmm\n";
  for (std::size_t i = 0; i < s.joints.size(); ++i) {
    const auto& j = s.joints[i];
    os << spine::vertebra_names()[i];
    for (int k = 0; k < 6; ++k) os << "," << s.displacement(Eigen::Index(i), k);
    os << "," << j.joint << "," << j.axial_n << "," << j.shear_ap_n << "," << j.shear_lat_n << ","
       << j.disc_axial_n << "," << j.disc_shear_n << "," << j.force_world_n.norm();
    for (int k = 0; k < 3; ++k) os << "," << j.moment_local_nmm(k);
    os << "\n";
  }
  return os.str();
}

namespace {

std::string fused_list(const spine::ModelOptions& o) {
  std::string fused;
  for (int j : o.fused_joints)
    fused += (fused.empty() ? "" : ", ") + spine::joint_names()[std::size_t(j)];
  return fused;
}

bool polynomial(const SpineSolveRun& r) {
  return r.request.solve.recruitment.criterion == spine::Criterion::Polynomial;
}

double max_reserve_nmm(const spine::SpineSolution& s) {
  return s.recruitment.reserve_nmm.size() ? s.recruitment.reserve_nmm.cwiseAbs().maxCoeff() : 0.0;
}

nlohmann::json loads_json(const SpineSolveRun& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& l : r.request.loads)
    out.push_back({{"vertebra", spine::vertebra_names()[std::size_t(l.vertebra)]},
                   {"force_n", to_json(l.force_n)},
                   {"moment_nmm", to_json(l.moment_nmm)},
                   {"point_mm",
                    to_json(l.has_point ? l.point_mm
                                        : r.model.vertebrae[std::size_t(l.vertebra)].centre_mm)}});
  return out;
}

nlohmann::json vertebrae_json(const spine::SpineSolution& s) {
  nlohmann::json out = nlohmann::json::array();
  const auto& names = spine::vertebra_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto row = s.displacement.row(Eigen::Index(i));
    out.push_back({{"name", names[i]},
                   {"translation_mm", {row(0), row(1), row(2)}},
                   {"rotation_deg", {row(3), row(4), row(5)}}});
  }
  return out;
}

nlohmann::json muscles_json(const spine::SpineModel& m, const spine::SpineSolution& s) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < m.muscles.size(); ++i) {
    const auto& mu = m.muscles[i];
    out.push_back({{"name", mu.name},
                   {"group", mu.group},
                   {"side", mu.side},
                   {"max_force_n", mu.max_force_n()},
                   {"recruited_force_n", value_or_zero(s.recruitment.force_n, i)},
                   {"activation", value_or_zero(s.recruitment.activation, i)},
                   {"tension_n", value_or_zero(s.muscle_force_n, i)}});
  }
  return out;
}

nlohmann::json ligaments_json(const spine::SpineModel& m, const spine::SpineSolution& s) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < m.ligaments.size(); ++i) {
    const auto& li = m.ligaments[i];
    out.push_back({{"name", li.name},
                   {"type", li.type},
                   {"joint", li.joint >= 0 ? spine::joint_names()[std::size_t(li.joint)] : ""},
                   {"force_n", value_or_zero(s.ligament_force_n, i)}});
  }
  return out;
}

nlohmann::json recruitment_json(const SpineSolveRun& r) {
  const spine::SpineSolution& s = r.solution;
  return {{"enabled", r.request.solve.recruit},
          {"success", s.recruitment.success},
          {"status", s.recruitment.status},
          {"iterations", s.recruitment.iterations},
          {"objective", s.recruitment.objective},
          {"max_constraint_violation_nmm", s.recruitment.max_constraint_violation_nmm},
          {"max_reserve_nmm", max_reserve_nmm(s)},
          {"reserve_nmm", to_json(s.recruitment.reserve_nmm)},
          {"seconds", s.recruitment.seconds}};
}

}  // namespace

SpineSolveRun run_spine_solve(const std::string& data_dir, const SpineSolveRequest& request) {
  SpineSolveRun r;
  r.request = request;
  const Timer t0;
  r.model = spine::load_spine_model(data_dir, request.model);
  r.model_seconds = t0.seconds();
  try {
    r.solution = spine::solve_spine(r.model, request.loads, request.solve);
  } catch (const spine::SolveError& e) {
    const std::string what = one_line(e.what());
    throw std::runtime_error(what.find("equilibrium") != std::string::npos
                                 ? what
                                 : "the spine did not reach equilibrium: " + what);
  }
  r.total_seconds = t0.seconds();
  return r;
}

nlohmann::json scoliosis_curve_json(const spine::ScoliosisCurve& c) {
  if (c.cobb_deg == 0) return nullptr;
  return {{"type", c.type},
          {"cobb_deg", c.cobb_deg},
          {"upper_end", c.upper_end},
          {"apex", c.apex},
          {"lower_end", c.lower_end},
          {"apical_rotation_deg", c.apical_rotation_deg},
          {"convex", c.convex_right ? "right" : "left"}};
}

nlohmann::json scoliosis_json(const spine::SpineModel& m) {
  const spine::ScoliosisCurve& c = m.scoliosis;
  if (c.cobb_deg == 0) return nullptr;
  const spine::ScoliosisPosture p = spine::scoliotic_posture(m, c);
  nlohmann::json j = scoliosis_curve_json(c);
  j["rest_posture"] = {{"cobb_deg", p.cobb_deg},
                       {"apex_offset_mm", p.apex_offset_mm},
                       {"apical_rotation_deg", p.apical_rotation_deg},
                       {"t1_offset_mm", p.t1_offset_mm},
                       {"t1_tilt_deg", p.t1_tilt_deg},
                       {"largest_disc_closure", p.largest_share},
                       {"largest_disc_closure_joint", p.largest_share_joint}};
  return j;
}

nlohmann::json spine_solve_json(const SpineSolveRun& r, const std::string& csv) {
  const spine::SpineSolution& s = r.solution;
  const spine::SolveOptions& options = r.request.solve;
  const spine::ModelOptions& model_options = r.request.model;
  const Eigen::Matrix<double, 6, 1>& b = s.bushing_wrench;
  nlohmann::json joints = nlohmann::json::array();
  for (const auto& j : s.joints) joints.push_back(joint_reaction_json(j));
  return {
      {"loads", loads_json(r)},
      {"options",
       {{"fusion", model_options.fused_joints.empty() ? nlohmann::json::array()
                                                      : nlohmann::json(fused_list(model_options))},
        {"muscles", options.recruit},
        {"gravity", model_options.gravity},
        {"ligaments", spine::ligaments_name(model_options.ligaments)},
        {"rib_cage", r.model.rib_cage != nullptr},
        {"scoliosis", scoliosis_json(r.model)},
        {"criterion", polynomial(r) ? "polynomial" : "minmax"},
        {"power", options.recruitment.power},
        {"tolerance_nmm", options.tolerance},
        {"max_iterations", options.max_iterations},
        {"subject", subject_json(r.model.subject)},
        {"muscle_strength", model_options.muscle_strength},
        {"joint_stiffness", model_options.joint_stiffness},
        {"ligament_stiffness", model_options.ligament_stiffness},
        {"inclination_deg", model_options.inclination_deg}}},
      {"converged", s.converged},
      {"iterations", s.iterations},
      {"gradient_norm_nmm", s.gradient_norm},
      {"stability",
       {{"min_stiffness_nmm_per_rad", s.min_stiffness_nmm_per_rad},
        {"stable", s.min_stiffness_nmm_per_rad > 0},
        {"softest_mode", s.softest_mode},
        {"sagittal_solve", s.sagittal_solve}}},
      {"vertebrae", vertebrae_json(s)},
      {"joints", joints},
      {"muscles", muscles_json(r.model, s)},
      {"ligaments", ligaments_json(r.model, s)},
      {"bushing",
       {{"enabled", r.model.has_bushing},
        {"force_n", {b(0), b(1), b(2)}},
        {"moment_nmm", {b(3), b(4), b(5)}}}},
      {"recruitment", recruitment_json(r)},
      {"warnings", s.warnings},
      {"seconds",
       {{"model", r.model_seconds},
        {"recruitment", s.seconds_recruitment},
        {"equilibrium", s.seconds_equilibrium},
        {"total", r.total_seconds}}},
      {"csv", path_or_null(csv)},
      {"units",
       {{"frame", "x lateral (body's right -x), y superior, z anterior"},
        {"translation_mm", "vertebra F.1 centre, world axes, mm"},
        {"rotation_deg", "rotation vector, world axes, deg"},
        {"joints",
         "force the lower side exerts on everything above: world N, N·mm about the moved joint "
         "point; "
         "axial/shear in the lower vertebra's axes (compression > 0); disc_* in the disc "
         "mid-plane; "
         "moment_local x flexion+, y torsion, z lateral bending"}}}};
}

namespace {

void print_header(std::ostream& os, const SpineSolveRun& r) {
  const spine::SpineModel& m = r.model;
  const spine::SpineSolution& s = r.solution;
  const auto& names = spine::vertebra_names();
  const std::string fused = fused_list(r.request.model);
  const std::string criterion =
      polynomial(r) ? "polynomial, p = " + fixed(r.request.solve.recruitment.power, 1) : "min-max";
  os << "Spine equilibrium (thesis 3.3): x lateral (body's right -x), y superior, z anterior\n"
     << "  model: " << (r.request.model.gravity ? "gravity" : "no gravity") << ", "
     << (r.request.solve.recruit ? "muscles recruited (" + criterion + ")" : "no muscles") << ", "
     << m.ligaments.size() << " ligaments" << (m.has_bushing ? ", IAP bushing" : "")
     << "; fusion: " << (fused.empty() ? "none" : fused) << "\n"
     << "  body: " << subject_text(m.subject) << "\n";
  if (m.rib_cage) os << "  rib cage: 24 ribs and the sternum on T1-T12\n";
  const spine::ModelOptions& mo = r.request.model;
  if (mo.muscle_strength != 1 || mo.joint_stiffness != 1 || mo.ligament_stiffness != 1 ||
      mo.inclination_deg != 0)
    os << "  inputs: muscle strength x" << significant(mo.muscle_strength, 4)
       << ", joint stiffness x" << significant(mo.joint_stiffness, 4) << ", ligament stiffness x"
       << significant(mo.ligament_stiffness, 4) << ", inclined forward "
       << significant(mo.inclination_deg, 4) << " deg\n";
  if (m.scoliosis.cobb_deg != 0) {
    const spine::ScoliosisPosture p = spine::scoliotic_posture(m, m.scoliosis);
    os << "  scoliosis: " << m.scoliosis.type << ", " << m.scoliosis.upper_end << "-"
       << m.scoliosis.lower_end << ", apex " << m.scoliosis.apex << ", convex "
       << (m.scoliosis.convex_right ? "right" : "left") << "; at rest Cobb "
       << fixed(p.cobb_deg, 1) << " deg, apex " << fixed(p.apex_offset_mm, 1)
       << " mm off the ends' line, apical rotation " << fixed(p.apical_rotation_deg, 1)
       << " deg\n";
  }
  for (std::size_t i = 0; i < r.request.loads.size(); ++i) {
    const auto& l = r.request.loads[i];
    os << "  load " << i + 1 << ": " << names[std::size_t(l.vertebra)];
    if (l.force_n.squaredNorm() > 0)
      os << " force " << vec3(l.force_n, 1) << " N at "
         << vec3(l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm, 1)
         << " mm";
    if (l.moment_nmm.squaredNorm() > 0) os << " couple " << vec3(l.moment_nmm, 1) << " N·mm";
    os << "\n";
  }
  if (r.request.loads.empty()) os << "  no external load (gravity only)\n";
  os << "  converged in " << s.iterations << " Newton iterations, max |dPi/dtheta| "
     << std::setprecision(2) << std::scientific << s.gradient_norm << std::defaultfloat
     << " N·mm\n";
  os << "  tangent stiffness: smallest eigenvalue " << std::setprecision(4)
     << s.min_stiffness_nmm_per_rad / 1000 << " N·m/rad ("
     << (s.min_stiffness_nmm_per_rad > 0 ? "stable" : "NOT stable") << "), softest mode "
     << s.softest_mode << "\n\n";
}

void print_vertebrae(std::ostream& os, const spine::SpineSolution& s) {
  const auto& names = spine::vertebra_names();
  TextTable v({"vertebra", "tx (mm)", "ty (mm)", "tz (mm)", "rx (deg)", "ry (deg)", "rz (deg)"});
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::vector<std::string> row{names[i]};
    for (int k = 0; k < 6; ++k)
      row.push_back(fixed(s.displacement(Eigen::Index(i), k), k < 3 ? 3 : 4));
    v.add(row);
  }
  os << "Vertebra displacement (centre translation, rotation vector; world axes)\n";
  v.print(os, false);
}

void print_joints(std::ostream& os, const SpineSolveRun& r) {
  const auto& fused = r.request.model.fused_joints;
  TextTable jt({"joint", "axial (N)", "shear AP (N)", "shear lat (N)", "disc axial (N)",
                "disc shear (N)", "|F| (N)", "Mx flex+ (N·m)", "My torsion (N·m)", "Mz lat (N·m)"});
  for (const auto& j : r.solution.joints)
    jt.add({j.joint +
                (std::find(fused.begin(), fused.end(), spine::joint_index(j.joint)) != fused.end()
                     ? " (fused)"
                     : ""),
            fixed(j.axial_n, 1), fixed(j.shear_ap_n, 1), fixed(j.shear_lat_n, 1),
            fixed(j.disc_axial_n, 1), fixed(j.disc_shear_n, 1), fixed(j.force_world_n.norm(), 1),
            fixed(j.moment_local_nmm.x() * 1e-3, 3), fixed(j.moment_local_nmm.y() * 1e-3, 3),
            fixed(j.moment_local_nmm.z() * 1e-3, 3)});
  os << "\nJoint reactions (lower side on everything above; joint frame = lower vertebra's axes, "
        "compression > 0)\n";
  jt.print(os, false);
}

void print_muscles(std::ostream& os, const spine::SpineModel& m, const spine::SpineSolution& s,
                   int top) {
  const Eigen::VectorXd& recruited = s.recruitment.force_n;
  if (m.muscles.empty() || recruited.size() != Eigen::Index(m.muscles.size())) return;
  int active = 0;
  for (Eigen::Index i = 0; i < recruited.size(); ++i)
    active += recruited(i) > 1e-3 * m.muscles[std::size_t(i)].max_force_n();
  TextTable mt(
      {"muscle", "group", "side", "recruited F (N)", "F max (N)", "activation", "tension (N)"}, 3);
  for (int i : top_indices(recruited, top)) {
    const auto& mu = m.muscles[std::size_t(i)];
    mt.add({mu.name, mu.group, mu.side, fixed(recruited(i), 1), fixed(mu.max_force_n(), 1),
            fixed(value_or_zero(s.recruitment.activation, std::size_t(i)), 3),
            fixed(value_or_zero(s.muscle_force_n, std::size_t(i)), 1)});
  }
  os << "\nMuscles: " << active << " of " << m.muscles.size()
     << " active (F > 0.1 % of F max); the "
     << std::min<std::size_t>(std::size_t(top), m.muscles.size())
     << " strongest (tension: at the equilibrium posture)\n";
  mt.print(os, false);
}

void print_ligaments(std::ostream& os, const spine::SpineModel& m, const spine::SpineSolution& s,
                     int top) {
  if (m.ligaments.empty() || s.ligament_force_n.size() != Eigen::Index(m.ligaments.size())) return;
  int taut = 0;
  for (Eigen::Index i = 0; i < s.ligament_force_n.size(); ++i) taut += s.ligament_force_n(i) > 0;
  TextTable lt({"ligament", "type", "joint", "force (N)"}, 3);
  for (int i : top_indices(s.ligament_force_n, top)) {
    if (s.ligament_force_n(i) <= 0) break;
    const auto& li = m.ligaments[std::size_t(i)];
    lt.add({li.name, li.type, li.joint >= 0 ? spine::joint_names()[std::size_t(li.joint)] : "-",
            fixed(s.ligament_force_n(i), 2)});
  }
  os << "\nLigaments: " << taut << " of " << m.ligaments.size() << " in tension; the strongest\n";
  lt.print(os, false);
}

void print_footer(std::ostream& os, const SpineSolveRun& r, const std::string& csv) {
  const spine::SpineModel& m = r.model;
  const spine::SpineSolution& s = r.solution;
  if (m.has_bushing) {
    const auto& b = s.bushing_wrench;
    os << "\nIAP bushing on the rib cage (" << spine::vertebra_names()[std::size_t(m.ribs_body)]
       << "): force " << vec3(Eigen::Vector3d(b(0), b(1), b(2)), 1) << " N, moment "
       << vec3(Eigen::Vector3d(b(3), b(4), b(5)) * 1e-3, 3) << " N·m\n";
  }
  if (r.request.solve.recruit)
    os << "Recruitment: " << (s.recruitment.success ? "success" : "FAILED") << " ("
       << s.recruitment.status << ", " << s.recruitment.iterations
       << " Ipopt iterations), objective " << std::setprecision(4) << s.recruitment.objective
       << ", max equilibrium violation " << fixed(s.recruitment.max_constraint_violation_nmm, 3)
       << " N·mm, largest reserve moment " << fixed(max_reserve_nmm(s) * 1e-3, 3) << " N·m\n";
  os << "Time: model " << fixed(r.model_seconds * 1e3, 1) << " ms, recruitment "
     << fixed(s.seconds_recruitment * 1e3, 1) << " ms, equilibrium "
     << fixed(s.seconds_equilibrium * 1e3, 1) << " ms, total " << fixed(r.total_seconds * 1e3, 1)
     << " ms" << (csv.empty() ? "" : "; wrote " + csv) << "\n";
}

}  // namespace

void print_spine_solve(std::ostream& os, const SpineSolveRun& r, int top, const std::string& csv) {
  print_header(os, r);
  print_vertebrae(os, r.solution);
  print_joints(os, r);
  if (r.request.solve.recruit) print_muscles(os, r.model, r.solution, top);
  print_ligaments(os, r.model, r.solution, top);
  print_footer(os, r, csv);
}

nlohmann::json subject_json(const spine::Subject& subject) {
  return {{"height_m", subject.height_m},
          {"body_mass_kg", subject.body_mass_kg},
          {"sex", spine::sex_name(subject.sex)}};
}

std::string subject_text(const spine::Subject& subject) {
  return std::string(spine::sex_name(subject.sex)) + ", " + fixed(subject.height_m, 3) + " m, " +
         fixed(subject.body_mass_kg, 1) + " kg";
}

}  // namespace spinesim::studies
