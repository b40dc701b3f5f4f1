// The seating studies (seating_study.hpp; docs/seating.md).
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/mesh/surface_distance.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {
namespace {
using Eigen::Vector3d;
using nlohmann::json;

/// A chair surface file as the spine's contact surface (chair frame).
class FileSurface : public spine::ContactSurface {
 public:
  explicit FileSurface(mesh::SurfaceDistance d) : d_(std::move(d)) {}
  double level(const Vector3d& x, Vector3d& g) const override { return d_.signed_distance(x, g); }

 private:
  mesh::SurfaceDistance d_;
};

bool back_muscle(const std::string& group) {
  return group.find("multifidus") != std::string::npos ||
         group.find("erector spinae") != std::string::npos ||
         group.find("quadratus lumborum") != std::string::npos;
}

json vec_json(const Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

std::string chair_line(const spine::Chair& c) {
  std::ostringstream s;
  if (c.surface) {
    s << "backrest from " << c.surface_name;
  } else if (c.backrest_height_mm <= 0) {
    s << "no backrest";
  } else {
    s << "backrest at " << fixed(c.backrest_recline_deg, 1) << " deg, "
      << fixed(c.backrest_height_mm, 0) << " mm high";
    if (c.lumbar_support_mm > 0)
      s << ", lumbar support " << fixed(c.lumbar_support_mm, 0) << " mm deep at "
        << fixed(c.lumbar_support_height_mm, 0) << " mm";
  }
  s << "; seat pan " << fixed(c.seat_angle_deg, 1) << " deg (+ front up)"
    << (c.armrests ? "; armrests" : "; no armrests");
  return s.str();
}

}  // namespace

std::shared_ptr<const spine::ContactSurface> read_chair_surface(const std::string& path) {
  mesh::SurfaceDistance d = mesh::read_surface_distance(path);
  const Vector3d span = d.upper() - d.lower();
  if (!(span.maxCoeff() <= 5000))
    throw std::invalid_argument(path + ": the surface spans " + fixed(span.maxCoeff(), 0) +
                                " mm; a chair file is in mm and under 5 m");
  return std::make_shared<FileSurface>(std::move(d));
}

void check_seating_request(const SeatingRequest& request) {
  spine::check_chair(request.chair);
  if (request.pelvic_tilt_deg && !(std::abs(*request.pelvic_tilt_deg) <= 60))
    throw std::invalid_argument("--pelvic-tilt must be a number within -60 … 60 deg");
  if (request.model.inclination_deg != 0)
    throw std::invalid_argument(
        "a forward inclination is a standing posture; a seated spine's is the chair's and the "
        "pelvis's (--pelvic-tilt)");
}

SeatingRun run_seating(const std::string& data_dir, const SeatingRequest& request) {
  Timer timer;
  SeatingRun run;
  run.request = request;
  check_seating_request(request);
  const spine::SpineModel standing = spine::load_spine_model(data_dir, request.model);
  run.sitter = spine::load_sitter(standing);
  if (request.pelvic_tilt_deg) run.sitter.pelvic_tilt_deg = *request.pelvic_tilt_deg;
  try {
    run.seated = spine::solve_seated(standing, request.chair, run.sitter);
  } catch (const spine::SolveError& e) {
    throw std::runtime_error(std::string("the seated spine did not reach equilibrium: ") +
                             e.what());
  }
  run.model = spine::seat_model(standing, request.chair, run.sitter, run.seated.pelvic_tilt_deg,
                                run.seated.ischia_forward_mm)
                  .model;
  const auto& F = run.seated.spine.muscle_force_n;
  for (std::size_t i = 0; i < run.model.muscles.size(); ++i) {
    const auto& mu = run.model.muscles[i];
    if (!back_muscle(mu.group)) continue;
    run.back_muscle_force_n += F[Eigen::Index(i)];
    run.back_muscle_max_activation =
        std::max(run.back_muscle_max_activation, F[Eigen::Index(i)] / mu.max_force_n());
  }
  run.seconds = timer.seconds();
  return run;
}

void print_seating(std::ostream& os, const SeatingRun& run, bool markdown) {
  const auto& s = run.seated;
  os << "Chair: " << chair_line(run.request.chair) << "\n";
  os << "Sitter: pelvis tilted back " << fixed(s.pelvic_tilt_deg, 1) << " deg ("
     << fixed(run.sitter.pelvic_tilt_deg, 1) << " sitting + " << fixed(s.lean_deg, 1)
     << " leaning onto the backrest), lumbar lordosis " << fixed(run.sitter.lumbar_flexion_deg, 1)
     << " deg flatter than standing; ischia " << fixed(s.ischia_forward_mm, 0)
     << " mm in front of the seat's back edge\n\n";
  os << "Contact between back and chair (thesis fig. 6.7; on the body, chair axes: y up, z "
        "forward)\n";
  TextTable contacts({"level", "gap (mm)", "Fy (N)", "Fz (N)", "|F| (N)"});
  for (const auto& c : s.contacts)
    contacts.add({c.name, std::isfinite(c.gap_mm) ? fixed(c.gap_mm, 1) : "-",
                  fixed(c.force_n.y(), 1), fixed(c.force_n.z(), 1), fixed(c.force_n.norm(), 1)});
  contacts.add({"backrest", "", fixed(s.backrest_force_n.y(), 1), fixed(s.backrest_force_n.z(), 1),
                fixed(s.backrest_force_n.norm(), 1)});
  contacts.add({"seat", "", fixed(s.seat_force_n.y(), 1), fixed(s.seat_force_n.z(), 1),
                fixed(s.seat_force_n.norm(), 1)});
  contacts.add({"armrests", "", fixed(s.armrest_force_n.y(), 1), fixed(s.armrest_force_n.z(), 1),
                fixed(s.armrest_force_n.norm(), 1)});
  contacts.print(os, markdown);
  os << "  body weight carried " << fixed(s.body_weight_n, 1)
     << " N (trunk, head, arms, pelvis); force balance residual "
     << significant(s.force_residual_n, 2) << " N; moment left for the hips "
     << fixed(s.hip_moment_nmm / 1000, 2) << " N·m; the seat needs a friction coefficient of "
     << fixed(s.seat_friction_needed, 2) << " to hold the pelvis\n\n";
  const auto& l5 = s.spine.joints.back();
  os << "L5-S1 (thesis fig. 6.8; joint frame: x lateral, y axial, z anterior)\n";
  TextTable l5s1({"", "x", "y", "z"});
  const Vector3d m = l5.moment_local_nmm / 1000;
  l5s1.add({"force (N)", fixed(l5.shear_lat_n, 1), fixed(l5.axial_n, 1), fixed(l5.shear_ap_n, 1)});
  l5s1.add({"moment (N·m)", fixed(m.x(), 2), fixed(m.y(), 2), fixed(m.z(), 2)});
  l5s1.print(os, markdown);
  os << "\nDisc loads and vertebra angles\n";
  TextTable discs({"joint", "compression (N)", "AP shear (N)", "disc axial (N)", "disc shear (N)",
                   "upper vertebra tilt (deg, + forward)"});
  for (std::size_t k = 0; k < s.spine.joints.size(); ++k) {
    const auto& j = s.spine.joints[k];
    discs.add({j.joint, fixed(j.axial_n, 1), fixed(j.shear_ap_n, 1), fixed(j.disc_axial_n, 1),
               fixed(j.disc_shear_n, 1), fixed(s.vertebra_angle_deg[k], 2)});
  }
  discs.print(os, markdown);
  os << "\nMuscles: back (multifidus, erector spinae, quadratus lumborum) "
     << fixed(run.back_muscle_force_n, 1) << " N in all, largest activation "
     << fixed(run.back_muscle_max_activation, 3) << "\n";
  TextTable muscles({"muscle", "group", "tension (N)", "activation"}, 2);
  std::vector<std::size_t> order(run.model.muscles.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto& T = s.spine.muscle_force_n;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return T[Eigen::Index(a)] > T[Eigen::Index(b)]; });
  for (std::size_t r = 0; r < std::min<std::size_t>(10, order.size()); ++r) {
    const auto& mu = run.model.muscles[order[r]];
    if (!(T[Eigen::Index(order[r])] > 0.01)) break;
    muscles.add({mu.name, mu.group, fixed(T[Eigen::Index(order[r])], 1),
                 fixed(T[Eigen::Index(order[r])] / mu.max_force_n(), 3)});
  }
  muscles.print(os, markdown);
  os << "\nSolved in " << fixed(s.seconds, 2) << " s: " << s.solves << " equilibria, "
     << s.lean_iterations << " lean steps, " << s.contact_rounds
     << " recruitment rounds at the last\n";
  for (const auto& w : s.warnings) os << "warning: " << w << "\n";
}

json seating_json(const SeatingRun& run) {
  const auto& s = run.seated;
  const auto& c = run.request.chair;
  json j;
  j["chair"] = {{"seat_angle_deg", c.seat_angle_deg},
                {"backrest_recline_deg", c.backrest_recline_deg},
                {"backrest_height_mm", c.backrest_height_mm},
                {"lumbar_support_mm", c.lumbar_support_mm},
                {"lumbar_support_height_mm", c.lumbar_support_height_mm},
                {"armrests", c.armrests},
                {"surface", c.surface ? json(c.surface_name) : json(nullptr)}};
  j["subject"] = subject_json(run.model.subject);
  j["sitter"] = {{"pelvic_tilt_deg", s.pelvic_tilt_deg},
                 {"sitting_tilt_deg", run.sitter.pelvic_tilt_deg},
                 {"lean_deg", s.lean_deg},
                 {"lumbar_flexion_deg", run.sitter.lumbar_flexion_deg},
                 {"ischia_forward_mm", s.ischia_forward_mm}};
  json contacts = json::array();
  for (const auto& k : s.contacts)
    contacts.push_back({{"level", k.name},
                        {"gap_mm", k.gap_mm},
                        {"force_n", vec_json(k.force_n)},
                        {"point_mm", vec_json(k.point_mm)}});
  j["contacts"] = contacts;
  j["backrest_force_n"] = vec_json(s.backrest_force_n);
  j["seat_force_n"] = vec_json(s.seat_force_n);
  j["armrest_force_n"] = vec_json(s.armrest_force_n);
  j["body_weight_n"] = s.body_weight_n;
  j["force_residual_n"] = s.force_residual_n;
  j["hip_moment_nmm"] = s.hip_moment_nmm;
  j["seat_friction_needed"] = s.seat_friction_needed;
  json joints = json::array();
  for (std::size_t k = 0; k < s.spine.joints.size(); ++k) {
    json r = joint_reaction_json(s.spine.joints[k]);
    r["upper_vertebra_tilt_deg"] = s.vertebra_angle_deg[k];
    joints.push_back(r);
  }
  j["joints"] = joints;
  json muscles = json::array();
  for (std::size_t i = 0; i < run.model.muscles.size(); ++i) {
    const auto& mu = run.model.muscles[i];
    const double t = s.spine.muscle_force_n[Eigen::Index(i)];
    muscles.push_back({{"name", mu.name},
                       {"group", mu.group},
                       {"tension_n", t},
                       {"activation", t / mu.max_force_n()}});
  }
  j["muscles"] = muscles;
  j["iap_bushing"] = {{"force_n", vec_json(s.spine.bushing_wrench.head<3>())},
                      {"moment_nmm", vec_json(s.spine.bushing_wrench.tail<3>())}};
  j["back_muscle_force_n"] = run.back_muscle_force_n;
  j["back_muscle_max_activation"] = run.back_muscle_max_activation;
  j["solves"] = s.solves;
  j["lean_iterations"] = s.lean_iterations;
  j["lean_balanced"] = s.lean_balanced;
  j["warnings"] = s.warnings;
  j["seconds"] = s.seconds;
  j["frames"] =
      "forces on the body in the chair's axes (x lateral, y up, z forward); joints in "
      "the lower vertebra's axes";
  j["units"] = {{"force", "N"}, {"moment", "N*mm"}, {"length", "mm"}, {"angle", "deg"}};
  return j;
}

std::string seating_csv(const SeatingRun& run) {
  const auto& s = run.seated;
  std::ostringstream os;
  os << "level,gap_mm,contact_fy_n,contact_fz_n,contact_n,joint_below,compression_n,shear_ap_n,"
        "disc_axial_n,disc_shear_n,moment_flexion_nmm,vertebra_tilt_deg\n";
  for (std::size_t i = 0; i < s.contacts.size(); ++i) {
    const auto& c = s.contacts[i];
    os << c.name << "," << c.gap_mm << "," << c.force_n.y() << "," << c.force_n.z() << ","
       << c.force_n.norm();
    if (i < s.spine.joints.size()) {
      const auto& j = s.spine.joints[i];
      os << "," << j.joint << "," << j.axial_n << "," << j.shear_ap_n << "," << j.disc_axial_n
         << "," << j.disc_shear_n << "," << j.moment_local_nmm.x() << ","
         << s.vertebra_angle_deg[i];
    } else {
      os << ",,,,,,,";
    }
    os << "\n";
  }
  return os.str();
}

const std::vector<std::string>& seating_parameters() {
  static const std::vector<std::string> p = {"backrest-recline", "lumbar-support", "seat-angle",
                                             "backrest-height", "pelvic-tilt"};
  return p;
}

SeatingRequest with_parameter(SeatingRequest r, const std::string& parameter, double value) {
  if (parameter == "backrest-recline")
    r.chair.backrest_recline_deg = value;
  else if (parameter == "lumbar-support")
    r.chair.lumbar_support_mm = value;
  else if (parameter == "seat-angle")
    r.chair.seat_angle_deg = value;
  else if (parameter == "backrest-height")
    r.chair.backrest_height_mm = value;
  else if (parameter == "pelvic-tilt")
    r.pelvic_tilt_deg = value;
  else {
    std::string names;
    for (const auto& p : seating_parameters()) names += (names.empty() ? "" : ", ") + p;
    throw std::invalid_argument("--parameter " + parameter + " is not one of: " + names);
  }
  return r;
}

}  // namespace spinesim::studies
