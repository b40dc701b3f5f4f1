// The spine studies: validation (thesis 3.4), fusion (6.1), trends (6.3–6.4). Protocols and
// definitions are in spine_studies.hpp.
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/input_file.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/studies/spine_solve.hpp"
#include "spinesim/studies/toolkit.hpp"

#include "spinesim/spine/kinematics.hpp"
#include "spinesim/spine/model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace spinesim::studies {

using spine::ExternalLoad;
using spine::JointReaction;
using spine::SpineModel;
using spine::SpineSolution;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

void begin(const StageHooks& h, const std::string& what) {
  if (h.begin) h.begin(what);
}
void end(const StageHooks& h, const std::string& detail) {
  if (h.end) h.end(detail);
}

/// data/spine/spine_model.json (the model reads it too; the studies need its "validation" and
/// "crate" blocks).
nlohmann::json read_spine_json(const std::string& data_dir) {
  const std::string path = data_dir + "/spine/spine_model.json";
  try {
    return read_json_file(path, "spine model file");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
}

double required(const nlohmann::json& j, const std::string& block, const std::string& key) {
  if (!j.contains(key) || !j.at(key).is_number())
    throw std::runtime_error("spine_model.json: " + block + "." + key +
                             " is missing or not a number");
  return j.at(key).get<double>();
}

double optional(const nlohmann::json& j, const std::string& key) {
  return j.contains(key) && j.at(key).is_number() ? j.at(key).get<double>() : kNaN;
}

/// The studies' solve: the model's defaults; the 600 N warning is the studies' own business.
spine::SolveOptions study_solve_options() {
  spine::SolveOptions o;
  o.warn_above_600n = false;
  return o;
}

ExternalLoad force_on(int vertebra, const Eigen::Vector3d& force_n) {
  ExternalLoad l;
  l.vertebra = vertebra;
  l.force_n = force_n;
  return l;
}

double resultant(const JointReaction& r) { return r.force_world_n.norm(); }

/// "T10-T11 1.23" for reports.
std::string at(const std::vector<std::string>& pairs, int i, double v, int decimals = 3) {
  return pairs[std::size_t(i)] + " " + fixed(v, decimals);
}

}  // namespace

// --- shared ------------------------------------------------------------------------------------

nlohmann::json findings_json(const std::vector<Finding>& findings) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& f : findings)
    a.push_back({{"id", f.id},
                 {"load", f.load},
                 {"thesis", f.thesis},
                 {"ours", f.ours},
                 {"match", f.match}});
  return a;
}

void print_findings(std::ostream& os, const std::vector<Finding>& findings, bool markdown,
                    const std::string& says) {
  TextTable t({"verdict", "load", says, "ours"}, 4);
  for (const auto& f : findings) t.add({f.match ? "MATCH" : "DIFFERS", f.load, f.thesis, f.ours});
  t.print(os, markdown);
}

double joint_shear_n(const JointReaction& r) { return std::hypot(r.shear_ap_n, r.shear_lat_n); }

nlohmann::json joint_reaction_json(const JointReaction& r) {
  return {{"joint", r.joint},
          {"force_world_n", to_json(r.force_world_n)},
          {"moment_world_nmm", to_json(r.moment_world_nmm)},
          {"resultant_n", resultant(r)},
          {"axial_n", r.axial_n},
          {"shear_ap_n", r.shear_ap_n},
          {"shear_lat_n", r.shear_lat_n},
          {"shear_n", joint_shear_n(r)},
          {"disc_axial_n", r.disc_axial_n},
          {"disc_shear_n", r.disc_shear_n},
          {"moment_local_nmm", to_json(r.moment_local_nmm)}};
}

const std::vector<LoadDirection>& t1_load_directions() {
  static const std::vector<LoadDirection> d = {{"forward", Eigen::Vector3d(0, 0, 1)},
                                               {"backward", Eigen::Vector3d(0, 0, -1)},
                                               {"lateral", Eigen::Vector3d(-1, 0, 0)}};
  return d;
}

// --- validation --------------------------------------------------------------------------------

bool McGillCase::axial_ok() const {
  return l5s1.axial_n >= axial_lo_n && l5s1.axial_n <= axial_hi_n;
}
bool McGillCase::shear_ok() const { return joint_shear_n(l5s1) <= shear_max_n; }
bool WilkeCase::ok() const { return std::abs(l4l5.axial_n - target_n) <= tolerance * target_n; }

namespace {

/// M_ext of spine_studies.hpp: e_x · Σ (x_k − p) × f_k over the weights on vertebrae and the
/// external loads, at their points in `poses`, plus the external couples; N·mm.
double external_moment_x(const SpineModel& m, const std::vector<ExternalLoad>& loads,
                         const std::vector<spine::Pose>& poses,
                         const Eigen::Vector3d& joint_point) {
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (const auto& w : m.weights)
    if (w.body != spine::kGround)
      moment += (spine::place(poses, w.body, w.point_mm) - joint_point).cross(w.force_n);
  for (const auto& l : loads) {
    const Eigen::Vector3d X =
        l.has_point ? l.point_mm : m.vertebrae[std::size_t(l.vertebra)].centre_mm;
    moment += (spine::place(poses, l.vertebra, X) - joint_point).cross(l.force_n) + l.moment_nmm;
  }
  return moment.x();
}

McGillCase mcgill_case(const std::string& data_dir, const spine::ModelOptions& model,
                       const nlohmann::json& v) {
  McGillCase c;
  c.target_moment_nmm = required(v, "validation", "mcgill_extension_moment_nmm");
  const auto& range = v.at("mcgill_axial_range_n");
  if (!range.is_array() || range.size() != 2)
    throw std::runtime_error("spine_model.json: validation.mcgill_axial_range_n must be [lo, hi]");
  c.axial_lo_n = range[0].get<double>();
  c.axial_hi_n = range[1].get<double>();
  c.shear_max_n = required(v, "validation", "mcgill_shear_max_n");
  c.thesis_force_n = optional(v, "thesis_mcgill_t7_force_n");
  c.thesis_axial_n = optional(v, "thesis_mcgill_axial_n");
  c.thesis_shear_n = optional(v, "thesis_mcgill_shear_n");
  c.dezee_axial_n = optional(v, "dezee_mcgill_axial_n");
  c.dezee_shear_n = optional(v, "dezee_mcgill_shear_n");
  c.source = v.value("mcgill_source", "");

  const SpineModel m = spine::load_spine_model(data_dir, model);
  const int t7 = spine::vertebra_index("T7");
  const int l5s1 = spine::joint_index("L5-S1");
  const Eigen::Vector3d p = m.joints[std::size_t(l5s1)].point_mm;
  const spine::SolveOptions options = study_solve_options();
  auto loads_for = [&](double f) {
    return std::vector<ExternalLoad>{force_on(t7, Eigen::Vector3d(0, 0, f))};
  };
  auto moment_at = [&](double f, SpineSolution* keep) {
    const auto loads = loads_for(f);
    SpineSolution s = spine::solve_spine(m, loads, options);
    ++c.solves;
    const double moment = external_moment_x(m, loads, s.poses, p);
    if (keep) *keep = std::move(s);
    return moment;
  };

  // Secant on g(F) = M_ext(F) − target from F = 0 and the rigid-lever estimate; M_ext is nearly
  // linear in F (the lever changes only with the posture).
  const double lever_mm = m.vertebrae[std::size_t(t7)].centre_mm.y() - p.y();
  SpineSolution s;
  double f0 = 0, g0 = moment_at(f0, nullptr) - c.target_moment_nmm;
  double f1 = -g0 / lever_mm, g1 = moment_at(f1, &s) - c.target_moment_nmm;
  const double tolerance_nmm = 1e-6 * std::abs(c.target_moment_nmm);
  for (int k = 0; std::abs(g1) > tolerance_nmm; ++k) {
    if (k == 30 || g1 == g0)
      throw std::runtime_error("McGill case: no T7 force found giving the L5-S1 moment " +
                               fixed(c.target_moment_nmm * 1e-3, 1) + " N·m after " +
                               std::to_string(c.solves) + " solves");
    const double f2 = f1 - g1 * (f1 - f0) / (g1 - g0);
    f0 = f1, g0 = g1;
    f1 = f2;
    g1 = moment_at(f1, &s) - c.target_moment_nmm;
  }
  c.t7_force_n = f1;
  c.external_moment_nmm = g1 + c.target_moment_nmm;
  c.external_moment_reference_nmm =
      external_moment_x(m, loads_for(f1), std::vector<spine::Pose>(m.vertebrae.size()), p);
  c.l5s1 = s.joints[std::size_t(l5s1)];
  c.joint_moment_nmm = c.l5s1.moment_world_nmm.x();
  c.other_moment_nmm = c.external_moment_nmm - c.joint_moment_nmm;
  c.iterations = s.iterations;
  return c;
}

WilkeCase wilke_case(const std::string& data_dir, const spine::ModelOptions& model,
                     const nlohmann::json& j) {
  const nlohmann::json& v = j.at("validation");
  if (!j.contains("crate"))
    throw std::runtime_error("spine_model.json: the crate block is missing");
  const nlohmann::json& crate = j.at("crate");
  WilkeCase c;
  c.target_n = required(v, "validation", "wilke_axial_n");
  c.tolerance = required(v, "validation", "wilke_tolerance");
  c.thesis_n = optional(v, "thesis_wilke_axial_n");
  c.crate_mass_kg = required(crate, "crate", "mass_kg");
  c.distance_from_chest_mm = required(crate, "crate", "distance_from_chest_mm");
  c.carried_by = crate.value("carried_by", "");
  c.source = crate.value("source", "");

  spine::ModelOptions mo = model;
  mo.arms_forward = true;
  const SpineModel m = spine::load_spine_model(data_dir, mo);
  c.crate_point_mm = m.chest_front_mm + Eigen::Vector3d(0, 0, c.distance_from_chest_mm);
  ExternalLoad crate_load =
      force_on(spine::vertebra_index(c.carried_by),
               Eigen::Vector3d(0, -c.crate_mass_kg * m.gravity_mm_s2 * 1e-3, 0));  // N = kg·m/s²
  crate_load.has_point = true;
  crate_load.point_mm = c.crate_point_mm;
  const SpineSolution s = spine::solve_spine(m, {crate_load}, study_solve_options());
  c.l4l5 = s.joints[std::size_t(spine::joint_index("L4-L5"))];
  c.iterations = s.iterations;
  return c;
}

}  // namespace

WilkeCase run_wilke_case(const std::string& data_dir, const spine::ModelOptions& model) {
  return wilke_case(data_dir, model, read_spine_json(data_dir));
}

ValidationStudy run_validation_study(const std::string& data_dir, const spine::ModelOptions& model,
                                     const StageHooks& hooks) {
  Timer t0;
  const nlohmann::json j = read_spine_json(data_dir);
  if (!j.contains("validation"))
    throw std::runtime_error("spine_model.json: the validation block is missing");
  ValidationStudy s;
  begin(hooks, "McGill & Norman: force on T7 for the L5-S1 moment");
  s.mcgill = mcgill_case(data_dir, model, j.at("validation"));
  end(hooks, std::to_string(s.mcgill.solves) + " solves");
  begin(hooks, "Wilke: crate held in front of the chest");
  s.wilke = wilke_case(data_dir, model, j);
  s.trunk_muscles = model.trunk_muscles;
  s.ligaments = spine::has_ligaments(model);
  s.subject = spine::resolve_subject(data_dir, model.subject);
  end(hooks, "");
  s.seconds = t0.seconds();
  return s;
}

void print_validation(std::ostream& os, const ValidationStudy& s, bool markdown) {
  const McGillCase& a = s.mcgill;
  const WilkeCase& b = s.wilke;
  auto verdict = [](bool ok) { return std::string(ok ? "pass" : "FAIL"); };
  TextTable t({"case", "quantity", "ours", "target", "thesis", "de Zee 2007", "verdict"}, 2);
  t.add(
      {"McGill", "T7 force (N)", fixed(a.t7_force_n, 1), "-", fixed(a.thesis_force_n, 0), "-", ""});
  t.add({"McGill", "L5-S1 external moment M_ext (N·m)", fixed(a.external_moment_nmm * 1e-3, 2),
         fixed(a.target_moment_nmm * 1e-3, 1), fixed(a.target_moment_nmm * 1e-3, 1),
         fixed(a.target_moment_nmm * 1e-3, 1), ""});
  t.add({"McGill", "of which the L5-S1 joint spring carries (N·m)",
         fixed(a.joint_moment_nmm * 1e-3, 2), "-", "-", "-", ""});
  t.add({"McGill", "of which muscles, ligaments, IAP carry (N·m)",
         fixed(a.other_moment_nmm * 1e-3, 2), "-", "-", "-", ""});
  t.add({"McGill", "L5-S1 axial, joint frame (N)", fixed(a.l5s1.axial_n, 1),
         fixed(a.axial_lo_n, 0) + "–" + fixed(a.axial_hi_n, 0), fixed(a.thesis_axial_n, 0),
         fixed(a.dezee_axial_n, 0), verdict(a.axial_ok())});
  t.add({"McGill", "L5-S1 shear, joint frame (N)", fixed(joint_shear_n(a.l5s1), 1),
         "≤ " + fixed(a.shear_max_n, 0), fixed(a.thesis_shear_n, 0), fixed(a.dezee_shear_n, 0),
         verdict(a.shear_ok())});
  t.add({"McGill", "L5-S1 AP shear +z, joint frame (N)", fixed(a.l5s1.shear_ap_n, 1), "-", "-", "-",
         ""});
  t.add({"McGill", "L5-S1 axial, disc frame (N)", fixed(a.l5s1.disc_axial_n, 1),
         fixed(a.axial_lo_n, 0) + "–" + fixed(a.axial_hi_n, 0), "-", "-", "(info)"});
  t.add({"McGill", "L5-S1 shear, disc frame (N)", fixed(a.l5s1.disc_shear_n, 1),
         "≤ " + fixed(a.shear_max_n, 0), "-", "-", "(info)"});
  t.add({"Wilke", "L4-L5 axial, joint frame (N)", fixed(b.l4l5.axial_n, 1),
         fixed(b.target_n, 0) + " ± " + fixed(100 * b.tolerance, 0) + " %", fixed(b.thesis_n, 1),
         "-", verdict(b.ok())});
  t.add({"Wilke", "L4-L5 axial, disc frame (N)", fixed(b.l4l5.disc_axial_n, 1), "-", "-", "-",
         "(info)"});
  t.add({"Wilke", "L4-L5 shear, joint frame (N)", fixed(joint_shear_n(b.l4l5), 1), "-", "-", "-",
         ""});
  t.print(os, markdown);
  os << (markdown ? "\n" : "") << "  McGill: +z force at the T7 centre, raised until M_ext = "
     << fixed(a.target_moment_nmm * 1e-3, 1) << " N·m (" << a.solves
     << " solves); M_ext = e_x·Σ(x−p_L5S1)×f over the T7\n"
     << "  force and the weights above L5-S1 in the equilibrium posture ("
     << fixed(a.external_moment_reference_nmm * 1e-3, 2)
     << " N·m in the reference posture); > 0 flexes the trunk.\n"
     << "  Wilke: " << fixed(b.crate_mass_kg, 1) << " kg crate at ("
     << fixed(b.crate_point_mm.x(), 0) << ", " << fixed(b.crate_point_mm.y(), 0) << ", "
     << fixed(b.crate_point_mm.z(), 0) << ") mm, " << fixed(b.distance_from_chest_mm, 0)
     << " mm in front of the chest, carried by " << b.carried_by << ", arms forward.\n"
     << "  Joint frame: the lower vertebra's axes (axial +y, compression > 0); disc frame: the "
        "disc mid-plane.\n";
}

nlohmann::json validation_json(const ValidationStudy& s) {
  const McGillCase& a = s.mcgill;
  const WilkeCase& b = s.wilke;
  nlohmann::json mcgill = {
      {"source", a.source},
      {"t7_force_n", a.t7_force_n},
      {"target_moment_nmm", a.target_moment_nmm},
      {"external_moment_nmm", a.external_moment_nmm},
      {"external_moment_reference_posture_nmm", a.external_moment_reference_nmm},
      {"moment_definition",
       "M_ext = e_x . sum_k (x_k - p_L5S1) x f_k over the T7 force and the weights above L5-S1 at "
       "their equilibrium "
       "positions; > 0 flexes the trunk (the extension moment the trunk must supply)"},
      {"joint_moment_nmm", a.joint_moment_nmm},
      {"muscles_ligaments_iap_moment_nmm", a.other_moment_nmm},
      {"axial_n", a.l5s1.axial_n},
      {"shear_n", joint_shear_n(a.l5s1)},
      {"shear_ap_n", a.l5s1.shear_ap_n},
      {"disc_axial_n", a.l5s1.disc_axial_n},
      {"disc_shear_n", a.l5s1.disc_shear_n},
      {"l5s1", joint_reaction_json(a.l5s1)},
      {"target", {{"axial_range_n", {a.axial_lo_n, a.axial_hi_n}}, {"shear_max_n", a.shear_max_n}}},
      {"thesis",
       {{"t7_force_n", a.thesis_force_n},
        {"axial_n", a.thesis_axial_n},
        {"shear_n", a.thesis_shear_n}}},
      {"de_zee", {{"axial_n", a.dezee_axial_n}, {"shear_n", a.dezee_shear_n}}},
      {"axial_ok", a.axial_ok()},
      {"shear_ok", a.shear_ok()},
      {"pass", a.axial_ok() && a.shear_ok()},
      {"solves", a.solves},
      {"newton_iterations", a.iterations}};
  nlohmann::json wilke = {
      {"source", b.source},
      {"crate",
       {{"mass_kg", b.crate_mass_kg},
        {"distance_from_chest_mm", b.distance_from_chest_mm},
        {"carried_by", b.carried_by},
        {"point_mm", to_json(b.crate_point_mm)}}},
      {"axial_n", b.l4l5.axial_n},
      {"disc_axial_n", b.l4l5.disc_axial_n},
      {"shear_n", joint_shear_n(b.l4l5)},
      {"l4l5", joint_reaction_json(b.l4l5)},
      {"target",
       {{"axial_n", b.target_n},
        {"tolerance", b.tolerance},
        {"axial_range_n", {b.target_n * (1 - b.tolerance), b.target_n * (1 + b.tolerance)}}}},
      {"thesis", {{"axial_n", b.thesis_n}}},
      {"relative_error", (b.l4l5.axial_n - b.target_n) / b.target_n},
      {"pass", b.ok()},
      {"newton_iterations", b.iterations}};
  return {{"study", "validation"},
          {"thesis", "3.4"},
          {"trunk_muscles", s.trunk_muscles},
          {"ligaments", s.ligaments},
          {"subject", subject_json(s.subject)},
          {"units",
           {{"force", "N"},
            {"moment", "N·mm"},
            {"frame", "x lateral (body's right -x), y superior, z anterior"},
            {"joint_frame",
             "the lower vertebra's axes: axial +y (compression > 0), shear_ap +z, shear_lat +x"},
            {"disc_frame", "disc mid-plane: axis from the lower to the upper vertebra centre"}}},
          {"mcgill", mcgill},
          {"wilke", wilke},
          {"pass", a.axial_ok() && a.shear_ok() && b.ok()},
          {"seconds", s.seconds}};
}

std::string validation_csv(const ValidationStudy& s) {
  const McGillCase& a = s.mcgill;
  const WilkeCase& b = s.wilke;
  std::ostringstream os;
  os << std::setprecision(10) << "case,quantity,unit,value,target_low,target_high,thesis,pass\n";
  auto row = [&](const char* c, const char* q, const char* unit, double v, double lo, double hi,
                 double thesis, const char* pass) {
    auto num = [](double x) { return std::isnan(x) ? std::string() : fixed(x, 4); };
    os << c << "," << q << "," << unit << "," << num(v) << "," << num(lo) << "," << num(hi) << ","
       << num(thesis) << "," << pass << "\n";
  };
  const char* yes_no[] = {"no", "yes"};
  row("mcgill", "t7_force", "N", a.t7_force_n, kNaN, kNaN, a.thesis_force_n, "");
  row("mcgill", "external_moment", "N*mm", a.external_moment_nmm, a.target_moment_nmm,
      a.target_moment_nmm, kNaN, "");
  row("mcgill", "joint_moment_x", "N*mm", a.joint_moment_nmm, kNaN, kNaN, kNaN, "");
  row("mcgill", "l5s1_axial_joint_frame", "N", a.l5s1.axial_n, a.axial_lo_n, a.axial_hi_n,
      a.thesis_axial_n, yes_no[a.axial_ok()]);
  row("mcgill", "l5s1_shear_joint_frame", "N", joint_shear_n(a.l5s1), kNaN, a.shear_max_n,
      a.thesis_shear_n, yes_no[a.shear_ok()]);
  row("mcgill", "l5s1_axial_disc_frame", "N", a.l5s1.disc_axial_n, a.axial_lo_n, a.axial_hi_n, kNaN,
      "");
  row("mcgill", "l5s1_shear_disc_frame", "N", a.l5s1.disc_shear_n, kNaN, a.shear_max_n, kNaN, "");
  row("wilke", "l4l5_axial_joint_frame", "N", b.l4l5.axial_n, b.target_n * (1 - b.tolerance),
      b.target_n * (1 + b.tolerance), b.thesis_n, yes_no[b.ok()]);
  row("wilke", "l4l5_axial_disc_frame", "N", b.l4l5.disc_axial_n, kNaN, kNaN, kNaN, "");
  return os.str();
}

// --- fusion ------------------------------------------------------------------------------------

const FusionRun& FusionStudy::run(const std::string& fusion, const std::string& load) const {
  for (const auto& r : runs)
    if (r.fusion == fusion && r.load == load) return r;
  throw std::out_of_range("fusion study: no run " + fusion + " / " + load);
}

namespace {

std::vector<Finding> fusion_findings(const FusionStudy& s) {
  std::vector<Finding> out;
  auto motion = [&](const std::string& f, const std::string& l) {
    return s.run(f, l).t1_translation_mm.norm();
  };
  auto l2l3 = [&](const std::string& f, const std::string& l) {
    return resultant(s.run(f, l).l2l3);
  };
  auto l5s1 = [&](const std::string& f, const std::string& l) {
    return resultant(s.run(f, l).l5s1);
  };
  const std::vector<std::string> fused = {"L3-L4", "L4-L5", "L3-L4-L5"};
  for (const auto& l : s.loads) {
    {  // 1. Every fusion reduces T1's motion.
      std::ostringstream ours;
      bool all = true;
      ours << "|T1 translation| (mm): normal " << fixed(motion("normal", l), 3);
      for (const auto& f : fused) {
        ours << ", " << f << " " << fixed(motion(f, l), 3);
        all = all && motion(f, l) < motion("normal", l);
      }
      out.push_back({"fusion-reduces-motion", l, "every fusion moves T1 less than the normal spine",
                     ours.str(), all});
    }
    {  // 2. L3-L4 restricts more than L4-L5; L3-L4-L5 the most.
      const double a = motion("L3-L4", l), b = motion("L4-L5", l), c = motion("L3-L4-L5", l);
      out.push_back({"l3l4-restricts-more-than-l4l5", l,
                     "fusion at L3-L4 moves T1 less than fusion at L4-L5",
                     "L3-L4 " + fixed(a, 3) + " mm, L4-L5 " + fixed(b, 3) + " mm", a < b});
      out.push_back({"l3l4l5-restricts-most", l, "fusion at L3-L4-L5 moves T1 least",
                     "L3-L4-L5 " + fixed(c, 3) + " mm vs " + fixed(std::min(a, b), 3) + " mm",
                     c < std::min(a, b)});
    }
    {  // 3. Adjacent-level forces rise with every fusion.
      std::ostringstream ours;
      bool all = true;
      ours << "resultant (N) L2-L3 / L5-S1: normal " << fixed(l2l3("normal", l), 1) << " / "
           << fixed(l5s1("normal", l), 1);
      for (const auto& f : fused) {
        ours << ", " << f << " " << fixed(l2l3(f, l), 1) << " / " << fixed(l5s1(f, l), 1);
        all = all && l2l3(f, l) > l2l3("normal", l) && l5s1(f, l) > l5s1("normal", l);
      }
      out.push_back({"adjacent-forces-rise", l,
                     "every fusion raises the L2-L3 and L5-S1 forces above the normal spine's",
                     ours.str(), all});
    }
    {  // 4. L3-L4-L5 raises them most.
      const double a2 = std::max(l2l3("L3-L4", l), l2l3("L4-L5", l)),
                   a5 = std::max(l5s1("L3-L4", l), l5s1("L4-L5", l));
      const double c2 = l2l3("L3-L4-L5", l), c5 = l5s1("L3-L4-L5", l);
      out.push_back({"l3l4l5-raises-most", l,
                     "fusion at L3-L4-L5 gives the largest L2-L3 and L5-S1 forces",
                     "L3-L4-L5 " + fixed(c2, 1) + " / " + fixed(c5, 1) + " N vs single-level max " +
                         fixed(a2, 1) + " / " + fixed(a5, 1) + " N",
                     c2 > a2 && c5 > a5});
    }
    {  // 5. L4-L5 fusion loads L2-L3 less than L3-L4 fusion; L5-S1 about equal.
      const double a = l2l3("L3-L4", l), b = l2l3("L4-L5", l);
      out.push_back(
          {"l4l5-loads-l2l3-less", l, "fusion at L4-L5 loads L2-L3 less than fusion at L3-L4",
           "L2-L3: L4-L5 fusion " + fixed(b, 1) + " N, L3-L4 fusion " + fixed(a, 1) + " N", b < a});
      const double c = l5s1("L3-L4", l), d = l5s1("L4-L5", l),
                   rel = std::abs(c - d) / (0.5 * (c + d));
      out.push_back({"l5s1-about-equal", l,
                     "L5-S1 force about equal for L3-L4 and L4-L5 fusion (within 5 %)",
                     "L3-L4 " + fixed(c, 1) + " N, L4-L5 " + fixed(d, 1) + " N (" +
                         fixed(100 * rel, 1) + " %)",
                     rel <= 0.05});
    }
  }
  return out;
}

}  // namespace

FusionStudy run_fusion_study(const std::string& data_dir, double force_n,
                             const spine::ModelOptions& model, const StageHooks& hooks) {
  if (!std::isfinite(force_n) || force_n <= 0)
    throw std::invalid_argument("fusion study: the force must be finite and > 0 N");
  Timer t0;
  FusionStudy s;
  s.trunk_muscles = model.trunk_muscles;
  s.ligaments = spine::has_ligaments(model);
  s.subject = spine::resolve_subject(data_dir, model.subject);
  s.force_n = force_n;
  s.fusions = {"normal", "L3-L4", "L4-L5", "L3-L4-L5"};
  for (const auto& d : t1_load_directions()) s.loads.push_back(d.name);
  const spine::SolveOptions options = study_solve_options();
  const int t1 = spine::vertebra_index("T1");
  const std::size_t l2l3 = std::size_t(spine::joint_index("L2-L3")),
                    l5s1 = std::size_t(spine::joint_index("L5-S1"));
  for (const auto& fusion : s.fusions) {
    begin(hooks, "fusion " + fusion + ": gravity only and " + std::to_string(s.loads.size()) +
                     " loads on T1");
    spine::ModelOptions mo = model;
    mo.fused_joints = fusion == "normal" ? std::vector<int>{} : spine::parse_fusion(fusion);
    const SpineModel m = spine::load_spine_model(data_dir, mo);
    const SpineSolution base = spine::solve_spine(m, {}, options);
    const Eigen::Vector3d c = m.vertebrae[std::size_t(t1)].centre_mm;
    for (const auto& d : t1_load_directions()) {
      Timer t_start;
      FusionRun r;
      r.fusion = fusion;
      r.load = d.name;
      r.force_n = force_n * d.direction;
      const SpineSolution sol = spine::solve_spine(m, {force_on(t1, r.force_n)}, options);
      r.t1_translation_mm =
          sol.poses[std::size_t(t1)].apply(c) - base.poses[std::size_t(t1)].apply(c);
      r.t1_total_translation_mm = sol.poses[std::size_t(t1)].apply(c) - c;
      r.t1_rotation_deg =
          kDegPerRad * spine::rotation_log(sol.poses[std::size_t(t1)].R *
                                           base.poses[std::size_t(t1)].R.transpose());
      r.l2l3 = sol.joints[l2l3];
      r.l5s1 = sol.joints[l5s1];
      r.iterations = sol.iterations;
      r.seconds = t_start.seconds();
      s.runs.push_back(r);
    }
    end(hooks, "");
  }
  s.findings = fusion_findings(s);
  s.seconds = t0.seconds();
  return s;
}

void print_fusion(std::ostream& os, const FusionStudy& s, bool markdown) {
  TextTable t(
      {"fusion", "load", "T1 |t| (mm)", "T1 t x,y,z (mm)", "T1 |rot| (deg)", "L2-L3 axial (N)",
       "L2-L3 shear (N)", "L2-L3 |F| (N)", "L5-S1 axial (N)", "L5-S1 shear (N)", "L5-S1 |F| (N)"},
      2);
  for (const auto& r : s.runs) {
    const Eigen::Vector3d& v = r.t1_translation_mm;
    t.add({r.fusion, r.load, fixed(v.norm(), 3),
           fixed(v.x(), 2) + ", " + fixed(v.y(), 2) + ", " + fixed(v.z(), 2),
           fixed(r.t1_rotation_deg.norm(), 3), fixed(r.l2l3.axial_n, 1),
           fixed(joint_shear_n(r.l2l3), 1), fixed(resultant(r.l2l3), 1), fixed(r.l5s1.axial_n, 1),
           fixed(joint_shear_n(r.l5s1), 1), fixed(resultant(r.l5s1), 1)});
  }
  t.print(os, markdown);
  os << (markdown ? "\n" : "") << "  " << fixed(s.force_n, 0)
     << " N on the T1 centre: forward +z, backward -z, lateral -x. T1 motion: the force's effect "
        "(minus the same\n"
     << "  model's gravity-only equilibrium); joint forces: totals (gravity, muscles, force), "
        "joint frame.\n\n";
  print_findings(os, s.findings, markdown);
}

nlohmann::json fusion_json(const FusionStudy& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : s.runs) {
    nlohmann::json a = joint_reaction_json(r.l2l3), b = joint_reaction_json(r.l5s1);
    runs.push_back({{"fusion", r.fusion},
                    {"load", r.load},
                    {"force_n", to_json(r.force_n)},
                    {"t1_translation_mm", to_json(r.t1_translation_mm)},
                    {"t1_translation_norm_mm", r.t1_translation_mm.norm()},
                    {"t1_rotation_deg", to_json(r.t1_rotation_deg)},
                    {"t1_rotation_norm_deg", r.t1_rotation_deg.norm()},
                    {"t1_total_translation_mm", to_json(r.t1_total_translation_mm)},
                    {"t1_total_translation_norm_mm", r.t1_total_translation_mm.norm()},
                    {"l2l3", a},
                    {"l5s1", b},
                    {"newton_iterations", r.iterations},
                    {"seconds", r.seconds}});
  }
  return {
      {"study", "fusion"},
      {"thesis", "6.1, fig. 6.1-6.6"},
      {"trunk_muscles", s.trunk_muscles},
          {"ligaments", s.ligaments},
          {"subject", subject_json(s.subject)},
      {"force_n", s.force_n},
      {"fusions", s.fusions},
      {"loads", s.loads},
      {"units",
       {{"t1_translation_mm",
         "T1 centre, the force's effect (minus the gravity-only equilibrium), mm"},
        {"t1_rotation_deg", "rotation vector of T1 relative to the gravity-only equilibrium, deg"},
        {"t1_total_translation_mm", "T1 centre from the reference posture (gravity and force), mm"},
        {"joints", "totals in the joint frame (lower vertebra's axes), N and N·mm"}}},
      {"runs", runs},
      {"findings", findings_json(s.findings)},
      {"seconds", s.seconds}};
}

std::string fusion_csv(const FusionStudy& s) {
  std::ostringstream os;
  os << std::setprecision(10)
     << "fusion,load,force_x_n,force_y_n,force_z_n,t1_tx_mm,t1_ty_mm,t1_tz_mm,t1_translation_mm,t1_"
        "rx_deg,t1_ry_deg,"
        "t1_rz_deg,t1_rotation_deg,t1_total_translation_mm,l2l3_axial_n,l2l3_shear_ap_n,l2l3_shear_"
        "lat_n,l2l3_resultant_n,l5s1_axial_n,"
        "l5s1_shear_ap_n,l5s1_shear_lat_n,l5s1_resultant_n\n";
  for (const auto& r : s.runs) {
    os << r.fusion << "," << r.load;
    for (int k = 0; k < 3; ++k) os << "," << r.force_n(k);
    for (int k = 0; k < 3; ++k) os << "," << r.t1_translation_mm(k);
    os << "," << r.t1_translation_mm.norm();
    for (int k = 0; k < 3; ++k) os << "," << r.t1_rotation_deg(k);
    os << "," << r.t1_rotation_deg.norm() << "," << r.t1_total_translation_mm.norm();
    for (const JointReaction* j : {&r.l2l3, &r.l5s1})
      os << "," << j->axial_n << "," << j->shear_ap_n << "," << j->shear_lat_n << ","
         << resultant(*j);
    os << "\n";
  }
  return os.str();
}

// --- trends ------------------------------------------------------------------------------------

namespace {

/// One column of a trend run (a quantity per pair) with the checks the thesis's statements need.
struct PairSeries {
  const std::vector<std::string>& pairs;
  Eigen::VectorXd v;
  int index(const std::string& pair) const {
    const auto it = std::find(pairs.begin(), pairs.end(), pair);
    if (it == pairs.end()) throw std::logic_error("trends: no pair " + pair);
    return int(it - pairs.begin());
  }
  double operator()(const std::string& pair) const { return v(index(pair)); }
  /// Pairs first..last (inclusive) with v·sign > 0, and how many there are.
  int count_sign(const std::string& first, const std::string& last, double sign) const {
    int n = 0;
    for (int i = index(first); i <= index(last); ++i) n += v(i) * sign > 0;
    return n;
  }
  int span(const std::string& first, const std::string& last) const {
    return index(last) - index(first) + 1;
  }
  int argmax() const {
    Eigen::Index i = 0;
    v.maxCoeff(&i);
    return int(i);
  }
  int argmin() const {
    Eigen::Index i = 0;
    v.minCoeff(&i);
    return int(i);
  }
  std::string name(int i) const { return pairs[std::size_t(i)]; }
  std::string show(const std::string& pair, int decimals = 3) const {
    return pair + " " + fixed((*this)(pair), decimals);
  }
  std::string show(int i, int decimals = 3) const { return at(pairs, i, v(i), decimals); }
};

bool one_of(const std::string& s, std::initializer_list<const char*> options) {
  for (const char* o : options)
    if (s == o) return true;
  return false;
}

PairSeries column(const TrendRun& r, bool rotation, int k) {
  return PairSeries{r.pairs, rotation ? Eigen::VectorXd(r.rotation_deg.col(k))
                                      : Eigen::VectorXd(r.translation_mm.col(k))};
}

std::string count_of(int n, int of, const std::string& what) {
  return std::to_string(n) + "/" + std::to_string(of) + " " + what;
}

void add(std::vector<Finding>& out, const char* id, const char* load, const std::string& thesis,
         const std::string& ours, bool match) {
  out.push_back({id, load, thesis, ours, match});
}

/// Lateral force (−x), translations: x shear, y compression, z negligible.
void lateral_translation_findings(const TrendRun& r, std::vector<Finding>& out) {
  const double sx = r.force_n.x() > 0 ? 1 : -1;
  const PairSeries dx = column(r, false, 0), dy = column(r, false, 1), dz = column(r, false, 2);
  const PairSeries ax{r.pairs, dx.v.cwiseAbs()}, comp{r.pairs, -dy.v};
  const int n = int(r.pairs.size());
  add(out, "lateral-shear-everywhere", "lateral",
      "upper vertebra moves further than the lower one at every pair (lateral shear)",
      count_of(dx.count_sign("T1-T2", "L4-L5", sx), n, "pairs with Δx along the force"),
      dx.count_sign("T1-T2", "L4-L5", sx) == n);
  add(out, "lateral-shear-peak", "lateral", "shearing peak at T10-T11",
      "max |Δx| (mm) at " + ax.show(ax.argmax()) + "; " + ax.show("T10-T11"),
      ax.name(ax.argmax()) == "T10-T11");
  add(out, "lateral-shear-least", "lateral", "least shearing at L4-L5",
      "min |Δx| (mm) at " + ax.show(ax.argmin()) + "; " + ax.show("L4-L5"),
      ax.name(ax.argmin()) == "L4-L5");
  add(out, "lateral-shear-pattern", "lateral",
      "shearing falls T1-T2→T5-T6, rises T6-T7→T10-T11, falls to L4-L5",
      "|Δx| (mm) " + ax.show("T1-T2") + ", " + ax.show("T5-T6") + ", " + ax.show("T6-T7") + ", " +
          ax.show("T10-T11") + ", " + ax.show("L4-L5"),
      ax("T5-T6") < ax("T1-T2") && ax("T10-T11") > ax("T6-T7") && ax("L4-L5") < ax("T10-T11"));
  add(out, "lateral-compression-everywhere", "lateral",
      "whole spine under compression (Δy < 0 at every pair)",
      count_of(comp.count_sign("T1-T2", "L4-L5", 1), n, "pairs with Δy < 0"),
      comp.count_sign("T1-T2", "L4-L5", 1) == n);
  add(out, "lateral-compression-max", "lateral", "largest compression at T10-T11 and T1-T2",
      "max −Δy (mm) at " + comp.show(comp.argmax(), 4),
      one_of(comp.name(comp.argmax()), {"T10-T11", "T1-T2"}));
  add(out, "lateral-compression-min", "lateral", "smallest compression at L4-L5",
      "min −Δy (mm) at " + comp.show(comp.argmin(), 4), comp.name(comp.argmin()) == "L4-L5");
  const double zmax = dz.v.cwiseAbs().maxCoeff(), xmax = ax.v.maxCoeff();
  add(out, "lateral-z-negligible", "lateral",
      "z relative translation very small (< 10 % of the largest |Δx|)",
      "max |Δz| " + fixed(zmax, 4) + " mm vs max |Δx| " + fixed(xmax, 4) + " mm",
      zmax < 0.1 * xmax);
}

/// Lateral force (−x), rotations: flexion negligible, torsion, lateral bending by region.
void lateral_rotation_findings(const TrendRun& r, std::vector<Finding>& out) {
  const PairSeries rx = column(r, true, 0), ry = column(r, true, 1), rz = column(r, true, 2);
  const PairSeries ary{r.pairs, ry.v.cwiseAbs()};
  const double rxmax = rx.v.cwiseAbs().maxCoeff(), rzmax = rz.v.cwiseAbs().maxCoeff();
  add(out, "lateral-flexion-negligible", "lateral",
      "flexion/extension negligible (max |θx| < 10 % of max |θz|)",
      "max |θx| " + fixed(rxmax, 4) + "°, max |θz| " + fixed(rzmax, 4) + "°", rxmax < 0.1 * rzmax);
  add(out, "lateral-torsion-min", "lateral", "smallest torsion at T10-T11",
      "min |θy| (deg) at " + ary.show(ary.argmin(), 4), ary.name(ary.argmin()) == "T10-T11");
  add(out, "lateral-torsion-max", "lateral", "largest torsion at T5-T6 and L4-L5",
      "max |θy| (deg) at " + ary.show(ary.argmax(), 4),
      one_of(ary.name(ary.argmax()), {"T5-T6", "L4-L5"}));
  {
    const double s1 = ry("T1-T2") >= 0 ? 1 : -1;
    const int up = ry.count_sign("T1-T2", "T10-T11", s1),
              low = ry.count_sign("T11-T12", "L4-L5", -s1);
    add(out, "lateral-torsion-switch", "lateral",
        "torsion one way T1-T2…T10-T11, the other way T11-T12…L4-L5",
        count_of(up, ry.span("T1-T2", "T10-T11"), "upper pairs one way") + ", " +
            count_of(low, ry.span("T11-T12", "L4-L5"), "lower pairs the other"),
        up == ry.span("T1-T2", "T10-T11") && low == ry.span("T11-T12", "L4-L5"));
  }
  {
    const double sl = rz("L4-L5") >= 0 ? 1 : -1;
    const int n_low = rz.count_sign("T10-T11", "L4-L5", sl);
    add(out, "lateral-bending-lower", "lateral", "T10-L5 in lateral flexion (one side)",
        count_of(n_low, rz.span("T10-T11", "L4-L5"), "pairs T10-T11…L4-L5 bend the same way"),
        n_low == rz.span("T10-T11", "L4-L5"));
    const double su = rz("T1-T2") >= 0 ? 1 : -1;
    const int a = rz.count_sign("T1-T2", "T5-T6", su), b = rz.count_sign("T6-T7", "T9-T10", -su);
    add(out, "lateral-bending-upper-opposite", "lateral", "T1-T6 and T6-T10 bend opposite ways",
        count_of(a, rz.span("T1-T2", "T5-T6"), "of T1-T2…T5-T6 one way") + ", " +
            count_of(b, rz.span("T6-T7", "T9-T10"), "of T6-T7…T9-T10 the other"),
        a == rz.span("T1-T2", "T5-T6") && b == rz.span("T6-T7", "T9-T10"));
  }
}

/// Forward force (+z): compression above T9, tension below, AP shear, flexion/extension regions.
void forward_findings(const TrendRun& r, std::vector<Finding>& out) {
  const double sz = r.force_n.z() > 0 ? 1 : -1;
  const PairSeries dy = column(r, false, 1), dz = column(r, false, 2);
  const PairSeries az{r.pairs, dz.v.cwiseAbs()}, comp{r.pairs, -dy.v};
  const int n = int(r.pairs.size());
  const int c_up = dy.count_sign("T1-T2", "T8-T9", -1), t_low = dy.count_sign("T9-T10", "L4-L5", 1);
  add(out, "forward-compression-T1-T9", "forward", "T1-T9 under compression (Δy < 0, T1-T2…T8-T9)",
      count_of(c_up, dy.span("T1-T2", "T8-T9"), "pairs"), c_up == dy.span("T1-T2", "T8-T9"));
  add(out, "forward-tension-T9-L5", "forward", "T9-L5 under tension (Δy > 0, T9-T10…L4-L5)",
      count_of(t_low, dy.span("T9-T10", "L4-L5"), "pairs"), t_low == dy.span("T9-T10", "L4-L5"));
  add(out, "forward-compression-max", "forward", "largest compression at T1-T2",
      "max −Δy (mm) at " + comp.show(comp.argmax(), 4), comp.name(comp.argmax()) == "T1-T2");
  add(out, "forward-tension-max", "forward", "maximum tension at T11-T12",
      "max Δy (mm) at " + dy.show(dy.argmax(), 4),
      dy.name(dy.argmax()) == "T11-T12" && dy.v.maxCoeff() > 0);
  add(out, "forward-shear-everywhere", "forward",
      "antero-posterior shear at every pair (Δz along the force)",
      count_of(dz.count_sign("T1-T2", "L4-L5", sz), n, "pairs"),
      dz.count_sign("T1-T2", "L4-L5", sz) == n);
  add(out, "forward-shear-max", "forward", "largest AP shear at T10-T11",
      "max |Δz| (mm) at " + az.show(az.argmax()), az.name(az.argmax()) == "T10-T11");
  add(out, "forward-shear-min", "forward", "smallest AP shear at L4-L5",
      "min |Δz| (mm) at " + az.show(az.argmin()), az.name(az.argmin()) == "L4-L5");
  add(out, "forward-shear-pattern", "forward",
      "AP shear rises T1-T2→T3-T4, falls T4-T5→T8-T9, rises to T10-T11, falls to L4-L5",
      "|Δz| (mm) " + az.show("T1-T2") + ", " + az.show("T3-T4") + ", " + az.show("T4-T5") + ", " +
          az.show("T8-T9") + ", " + az.show("T10-T11") + ", " + az.show("L4-L5"),
      az("T3-T4") > az("T1-T2") && az("T8-T9") < az("T4-T5") && az("T10-T11") > az("T8-T9") &&
          az("L4-L5") < az("T10-T11"));

  const PairSeries rx = column(r, true, 0);
  const int f1 = rx.count_sign("T1-T2", "T6-T7", 1), e = rx.count_sign("T7-T8", "T10-T11", -1),
            f2 = rx.count_sign("T11-T12", "L4-L5", 1);
  add(out, "forward-flexion-regions", "forward", "flexion T1-T7 and T11-L5, extension T7-T11",
      "flexion " + count_of(f1, rx.span("T1-T2", "T6-T7"), "of T1-T2…T6-T7") + ", extension " +
          count_of(e, rx.span("T7-T8", "T10-T11"), "of T7-T8…T10-T11") + ", flexion " +
          count_of(f2, rx.span("T11-T12", "L4-L5"), "of T11-T12…L4-L5"),
      f1 == rx.span("T1-T2", "T6-T7") && e == rx.span("T7-T8", "T10-T11") &&
          f2 == rx.span("T11-T12", "L4-L5"));
  add(out, "forward-flexion-max", "forward", "maximum flexion at T5-T6",
      "max θx (deg) at " + rx.show(rx.argmax(), 4), rx.name(rx.argmax()) == "T5-T6");
  add(out, "forward-extension-max", "forward", "maximum extension at T9-T10",
      "min θx (deg) at " + rx.show(rx.argmin(), 4),
      rx.name(rx.argmin()) == "T9-T10" && rx.v.minCoeff() < 0);
}

/// Backward force (−z): compression, AP shear, extension/flexion regions.
void backward_findings(const TrendRun& r, std::vector<Finding>& out) {
  const double sz = r.force_n.z() > 0 ? 1 : -1;
  const PairSeries dy = column(r, false, 1), dz = column(r, false, 2);
  const PairSeries az{r.pairs, dz.v.cwiseAbs()}, comp{r.pairs, -dy.v};
  const int n = int(r.pairs.size());
  add(out, "backward-compression-everywhere", "backward",
      "whole spine under compression (Δy < 0 at every pair)",
      count_of(comp.count_sign("T1-T2", "L4-L5", 1), n, "pairs"),
      comp.count_sign("T1-T2", "L4-L5", 1) == n);
  add(out, "backward-compression-max", "backward", "maximum compression at T11-T12",
      "max −Δy (mm) at " + comp.show(comp.argmax(), 4), comp.name(comp.argmax()) == "T11-T12");
  add(out, "backward-compression-min", "backward", "minimum compression at T6-T7 and L4-L5",
      "min −Δy (mm) at " + comp.show(comp.argmin(), 4),
      one_of(comp.name(comp.argmin()), {"T6-T7", "L4-L5"}));
  add(out, "backward-compression-pattern", "backward",
      "compression rises T8-T9→T11-T12, then falls to L4-L5",
      "−Δy (mm) " + comp.show("T8-T9", 4) + ", " + comp.show("T11-T12", 4) + ", " +
          comp.show("L4-L5", 4),
      comp("T11-T12") > comp("T8-T9") && comp("L4-L5") < comp("T11-T12"));
  add(out, "backward-shear-everywhere", "backward", "AP shear at every pair (Δz along the force)",
      count_of(dz.count_sign("T1-T2", "L4-L5", sz), n, "pairs"),
      dz.count_sign("T1-T2", "L4-L5", sz) == n);
  add(out, "backward-shear-max", "backward", "largest AP shear at T1-T2 and T10-T11",
      "max |Δz| (mm) at " + az.show(az.argmax()),
      one_of(az.name(az.argmax()), {"T1-T2", "T10-T11"}));
  add(out, "backward-shear-min", "backward", "smallest AP shear at L4-L5",
      "min |Δz| (mm) at " + az.show(az.argmin()), az.name(az.argmin()) == "L4-L5");
  add(out, "backward-shear-pattern", "backward",
      "AP shear falls T1-T2→T5-T6, rises T6-T7→T10-T11, falls to L4-L5",
      "|Δz| (mm) " + az.show("T1-T2") + ", " + az.show("T5-T6") + ", " + az.show("T6-T7") + ", " +
          az.show("T10-T11") + ", " + az.show("L4-L5"),
      az("T5-T6") < az("T1-T2") && az("T10-T11") > az("T6-T7") && az("L4-L5") < az("T10-T11"));

  const PairSeries rx = column(r, true, 0);
  const int e1 = rx.count_sign("T1-T2", "T5-T6", -1), f = rx.count_sign("T6-T7", "T9-T10", 1),
            e2 = rx.count_sign("T10-T11", "L4-L5", -1);
  add(out, "backward-extension-regions", "backward", "extension T1-T6 and T10-L5, flexion T6-T10",
      "extension " + count_of(e1, rx.span("T1-T2", "T5-T6"), "of T1-T2…T5-T6") + ", flexion " +
          count_of(f, rx.span("T6-T7", "T9-T10"), "of T6-T7…T9-T10") + ", extension " +
          count_of(e2, rx.span("T10-T11", "L4-L5"), "of T10-T11…L4-L5"),
      e1 == rx.span("T1-T2", "T5-T6") && f == rx.span("T6-T7", "T9-T10") &&
          e2 == rx.span("T10-T11", "L4-L5"));
  add(out, "backward-extension-max", "backward", "largest extension at T5-T6 and L1-L2",
      "min θx (deg) at " + rx.show(rx.argmin(), 4),
      one_of(rx.name(rx.argmin()), {"T5-T6", "L1-L2"}) && rx.v.minCoeff() < 0);
  add(out, "backward-flexion-max", "backward", "largest flexion at T6-T7",
      "max θx (deg) at " + rx.show(rx.argmax(), 4),
      rx.name(rx.argmax()) == "T6-T7" && rx.v.maxCoeff() > 0);
}

std::vector<Finding> trend_findings(const TrendsStudy& s) {
  auto run = [&](const std::string& load) -> const TrendRun& {
    for (const auto& r : s.runs)
      if (r.load == load) return r;
    throw std::logic_error("trends: no run " + load);
  };
  std::vector<Finding> out;
  lateral_translation_findings(run("lateral"), out);
  lateral_rotation_findings(run("lateral"), out);
  forward_findings(run("forward"), out);
  backward_findings(run("backward"), out);
  return out;
}

}  // namespace

TrendsStudy run_trends_study(const std::string& data_dir, double force_n,
                             const spine::ModelOptions& model, const StageHooks& hooks) {
  if (!std::isfinite(force_n) || force_n <= 0)
    throw std::invalid_argument("trends study: the force must be finite and > 0 N");
  Timer t0;
  TrendsStudy s;
  s.force_n = force_n;
  begin(hooks, "trends: gravity only and 3 loads on T1");
  s.trunk_muscles = model.trunk_muscles;
  s.ligaments = spine::has_ligaments(model);
  s.subject = spine::resolve_subject(data_dir, model.subject);
  const SpineModel m = spine::load_spine_model(data_dir, model);
  const spine::SolveOptions options = study_solve_options();
  const int t1 = spine::vertebra_index("T1");
  const int n_pairs = int(m.vertebrae.size()) - 1;  // T1-T2 … L4-L5: joints 0 … 15
  std::vector<std::string> pairs(spine::joint_names().begin(),
                                 spine::joint_names().begin() + n_pairs);
  // Relative translation (upper minus lower centre displacement) and θ per pair, one solution.
  auto relative = [&](const SpineSolution& sol, Eigen::MatrixX3d& t, Eigen::MatrixX3d& r) {
    t.resize(n_pairs, 3);
    r.resize(n_pairs, 3);
    for (int i = 0; i < n_pairs; ++i) {
      t.row(i) = sol.displacement.row(i).head<3>() - sol.displacement.row(i + 1).head<3>();
      r.row(i) = kDegPerRad * sol.theta.segment<3>(3 * i).transpose();
    }
  };
  Eigen::MatrixX3d base_t, base_r;
  relative(spine::solve_spine(m, {}, options), base_t, base_r);
  for (const char* name : {"lateral", "forward", "backward"}) {
    const auto& dirs = t1_load_directions();
    const auto d = std::find_if(dirs.begin(), dirs.end(),
                                [&](const LoadDirection& x) { return x.name == name; });
    TrendRun r;
    r.load = name;
    r.force_n = force_n * d->direction;
    r.pairs = pairs;
    const SpineSolution sol = spine::solve_spine(m, {force_on(t1, r.force_n)}, options);
    relative(sol, r.translation_mm, r.rotation_deg);
    r.translation_mm -= base_t;
    r.rotation_deg -= base_r;
    r.iterations = sol.iterations;
    s.runs.push_back(std::move(r));
  }
  end(hooks, "");
  s.findings = trend_findings(s);
  s.seconds = t0.seconds();
  return s;
}

void print_trends(std::ostream& os, const TrendsStudy& s, bool markdown) {
  for (const auto& r : s.runs) {
    os << (markdown ? "**" : "  ") << r.load << " force (" << fixed(r.force_n.x(), 0) << ", "
       << fixed(r.force_n.y(), 0) << ", " << fixed(r.force_n.z(), 0) << ") N on T1"
       << (markdown ? "**\n\n" : "\n");
    TextTable t({"pair", "Δx (mm)", "Δy (mm)", "Δz (mm)", "θx flex+ (deg)", "θy torsion (deg)",
                 "θz lat. bend (deg)"});
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const auto k = Eigen::Index(i);
      t.add({r.pairs[i], fixed(r.translation_mm(k, 0), 4), fixed(r.translation_mm(k, 1), 4),
             fixed(r.translation_mm(k, 2), 4), fixed(r.rotation_deg(k, 0), 4),
             fixed(r.rotation_deg(k, 1), 4), fixed(r.rotation_deg(k, 2), 4)});
    }
    t.print(os, markdown);
    os << "\n";
  }
  os << "  Δ = upper minus lower vertebra centre (world axes), θ = joint rotation (lower "
        "vertebra's axes), each minus its\n"
     << "  gravity-only value. Thesis reading: Δy < 0 compression, Δy > 0 tension, |Δx|, |Δz| "
        "shearing.\n\n";
  print_findings(os, s.findings, markdown);
  int matches = 0;
  for (const auto& f : s.findings) matches += f.match;
  os << (markdown ? "\n" : "") << "  " << matches << " of " << s.findings.size()
     << " thesis statements match.\n";
}

nlohmann::json trends_json(const TrendsStudy& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : s.runs) {
    nlohmann::json pairs = nlohmann::json::array();
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const auto k = Eigen::Index(i);
      pairs.push_back({{"pair", r.pairs[i]},
                       {"translation_mm", to_json(r.translation_mm.row(k).transpose())},
                       {"rotation_deg", to_json(r.rotation_deg.row(k).transpose())}});
    }
    runs.push_back({{"load", r.load},
                    {"force_n", to_json(r.force_n)},
                    {"pairs", pairs},
                    {"newton_iterations", r.iterations}});
  }
  int matches = 0;
  for (const auto& f : s.findings) matches += f.match;
  return {{"study", "trends"},
          {"thesis", "6.3 (relative translations), 6.4 (relative rotations)"},
          {"trunk_muscles", s.trunk_muscles},
          {"ligaments", s.ligaments},
          {"subject", subject_json(s.subject)},
          {"force_n", s.force_n},
          {"units",
           {{"translation_mm",
             "upper minus lower F.1 centre, world axes, minus the gravity-only value, mm"},
            {"rotation_deg",
             "joint rotation vector (lower vertebra's axes: x flexion +, y torsion, z lateral "
             "bending) minus the gravity-only value, deg"}}},
          {"runs", runs},
          {"findings", findings_json(s.findings)},
          {"matches", matches},
          {"statements", s.findings.size()},
          {"seconds", s.seconds}};
}

std::string trends_csv(const TrendsStudy& s) {
  std::ostringstream os;
  os << std::setprecision(10)
     << "load,pair,dx_mm,dy_mm,dz_mm,theta_x_deg,theta_y_deg,theta_z_deg\n";
  for (const auto& r : s.runs)
    for (std::size_t i = 0; i < r.pairs.size(); ++i) {
      const auto k = Eigen::Index(i);
      os << r.load << "," << r.pairs[i];
      for (int c = 0; c < 3; ++c) os << "," << r.translation_mm(k, c);
      for (int c = 0; c < 3; ++c) os << "," << r.rotation_deg(k, c);
      os << "\n";
    }
  return os.str();
}

}  // namespace spinesim::studies
