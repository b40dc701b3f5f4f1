// `spinesim study scoliosis` (scoliosis_study.hpp).
#include "spinesim/studies/scoliosis_study.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include <cmath>
#include <stdexcept>

namespace spinesim::studies {
namespace {

constexpr double kCobbs[] = {20, 40, 60};

spine::SpineSolution stand(const spine::SpineModel& m, bool loaded) {
  spine::SolveOptions o;
  o.warn_above_600n = false;
  o.recruit = loaded;
  return spine::solve_spine(m, {}, o);
}

/// The curve's discs under gravity with the muscles recruited, and its apical discs unloaded.
void run_case(const std::string& data_dir, spine::ModelOptions o, ScoliosisCase& c) {
  o.scoliosis = c.curve;
  spine::SpineModel m;
  try {
    m = spine::load_spine_model(data_dir, o);
  } catch (const std::invalid_argument& e) {
    c.refusal = e.what();
    return;
  }
  c.apex_offset_mm = spine::scoliotic_posture(m, c.curve).apex_offset_mm;
  const spine::SpineSolution s = stand(m, true);
  const int u = spine::vertebra_index(c.curve.upper_end), a = spine::vertebra_index(c.curve.apex),
            l = spine::vertebra_index(c.curve.lower_end);
  // Joint k's disc stresses for a solution's reaction there (the disc's section is the joint's).
  auto edge = [&m](const spine::SpineSolution& sol, int k) {
    const spine::Joint& j = m.joints[std::size_t(k)];
    return disc_edge_stress(sol.joints[std::size_t(k)], j.disc_width_mm, j.disc_depth_mm);
  };
  double most = -1e300;
  for (int k = u; k < l; ++k) {
    const DiscEdgeStress e = edge(s, k);
    ScoliosisDisc d;
    d.joint = s.joints[std::size_t(k)].joint;
    d.axial_n = s.joints[std::size_t(k)].disc_axial_n;
    d.lateral_moment_nmm = s.joints[std::size_t(k)].moment_local_nmm.z();
    // The concavity faces away from the convex side: left (+x) for a right-convex curve.
    d.concave_mpa = c.curve.convex_right ? e.left_mpa : e.right_mpa;
    d.convex_mpa = c.curve.convex_right ? e.right_mpa : e.left_mpa;
    if (d.concave_mpa - d.convex_mpa > most) {
      most = d.concave_mpa - d.convex_mpa;
      c.most_asymmetric = d.joint;
    }
    if (k == a - 1 || k == a) {  // the discs above and below the apex
      c.apical_concave_mpa += 0.5 * d.concave_mpa;
      c.apical_convex_mpa += 0.5 * d.convex_mpa;
    }
    c.discs.push_back(d);
  }
  o.gravity = o.muscles = false;
  const spine::SpineModel bare = spine::load_spine_model(data_dir, o);
  const spine::SpineSolution r = stand(bare, false);
  for (int k : {a - 1, a}) c.unloaded_apical_mpa += 0.5 * edge(r, k).mean_mpa;
}

std::vector<ScoliosisFinding> findings(const std::vector<ScoliosisCase>& cases) {
  int posed = 0, concave = 0, near_apex = 0;
  double unloaded = 0;
  for (const auto& c : cases) {
    if (!c.refusal.empty()) continue;
    ++posed;
    concave += c.apical_concave_mpa > c.apical_convex_mpa;
    const int apex = spine::vertebra_index(c.curve.apex),
              most = spine::joint_index(c.most_asymmetric);
    near_apex += most >= apex - 2 && most <= apex + 1;  // within a disc of the apical two
    unloaded = std::max(unloaded, std::abs(c.unloaded_apical_mpa));
  }
  const std::string of = " of " + std::to_string(posed) + " curves";
  return {
      {"Meir et al. 2007 (in vivo, 25 discs of 7 patients, during surgery)",
       "stress peaks in the concave annulus: the concave side more loaded at the apex",
       "concave edge above the convex one at the apical discs in " + std::to_string(concave) + of,
       posed > 0 && concave == posed},
      {"Meir et al. 2007",
       "0.25 MPa mean pressure in scoliotic discs without muscle load (< 0.07 MPa in other "
       "anaesthetised patients)",
       "largest unloaded apical stress " + fixed(unloaded, 3) +
           " MPa: the model's curve rests stress-free",
       unloaded >= 0.07},
      {"Modi et al. 2008 (150 patients; indirect, through Hueter-Volkmann)",
       "discs and bodies most wedged at the apex: the loading most asymmetric there",
       "most asymmetric disc within a level of the apex in " + std::to_string(near_apex) + of,
       posed > 0 && near_apex == posed}};
}

}  // namespace

DiscEdgeStress disc_edge_stress(const spine::JointReaction& r, double width_mm, double depth_mm) {
  if (!(width_mm > 0) || !(depth_mm > 0))
    throw std::invalid_argument("disc_edge_stress: the disc's width and depth must be > 0 mm");
  const double area = M_PI * width_mm * depth_mm / 4;
  const double inertia = M_PI * depth_mm * std::pow(width_mm, 3) / 64;
  // moment_local z > 0: the load bends the part above toward −x (its right), pressing the
  // right edge of the disc.
  const double bending = r.moment_local_nmm.z() * 0.5 * width_mm / inertia;
  DiscEdgeStress e;
  e.mean_mpa = r.disc_axial_n / area;
  e.right_mpa = e.mean_mpa + bending;
  e.left_mpa = e.mean_mpa - bending;
  return e;
}

ScoliosisStudy run_scoliosis_study(const std::string& data_dir, const spine::ModelOptions& model,
                                   const StageHooks& hooks) {
  Timer timer;
  ScoliosisStudy s;
  s.subject = spine::resolve_subject(data_dir, model.subject);
  for (const std::string& type : spine::scoliosis_curve_types()) {
    hooks.begin_stage("scoliosis: " + type + " curves, Cobb 20, 40, 60 deg");
    for (double cobb : kCobbs) {
      ScoliosisCase c;
      c.curve = spine::scoliosis_curve(type, cobb);
      run_case(data_dir, model, c);
      s.cases.push_back(c);
    }
    hooks.end_stage();
  }
  s.findings = findings(s.cases);
  s.seconds = timer.seconds();
  return s;
}

void print_scoliosis_study(std::ostream& os, const ScoliosisStudy& s) {
  os << "Standing under gravity, muscles recruited; the two discs next to the apex, compressive "
        "stress at their\nconcave and convex lateral edges (N/A ± M c / I on the disc's elliptic "
        "section; MPa)\n\n";
  TextTable t({"curve", "Cobb (deg)", "apex", "apex offset (mm)", "concave (MPa)", "convex (MPa)",
               "most asymmetric disc", "unloaded (MPa)"},
              1);
  for (const auto& c : s.cases) {
    const std::string name = c.curve.type + (c.curve.convex_right ? " (right)" : " (left)");
    if (!c.refusal.empty()) {
      t.add({name, fixed(c.curve.cobb_deg, 0), c.curve.apex, "cannot be posed", "", "", "", ""});
      continue;
    }
    t.add({name, fixed(c.curve.cobb_deg, 0), c.curve.apex, fixed(c.apex_offset_mm, 1),
           fixed(c.apical_concave_mpa, 3), fixed(c.apical_convex_mpa, 3), c.most_asymmetric,
           fixed(c.unloaded_apical_mpa, 3)});
  }
  t.print(os, false);
  for (const auto& c : s.cases)
    if (!c.refusal.empty())
      os << "\n  " << c.curve.type << " " << fixed(c.curve.cobb_deg, 0) << " deg: " << c.refusal;
  os << "\n\n";
  TextTable f({"source", "finding", "model", "verdict"}, 3);
  for (const auto& x : s.findings)
    f.add({x.source, x.finding, x.model, x.match ? "MATCH" : "DIFFERS"});
  f.print(os, false);
  os << "\n  The joint spring is the whole motion segment (facets and ligaments included); the "
        "edge stresses put\n  all of its moment on the disc. Body: "
     << subject_text(s.subject) << ". " << fixed(s.seconds, 1) << " s.\n";
}

nlohmann::json scoliosis_study_json(const ScoliosisStudy& s) {
  nlohmann::json cases = nlohmann::json::array(), found = nlohmann::json::array();
  for (const auto& c : s.cases) {
    nlohmann::json discs = nlohmann::json::array();
    for (const auto& d : c.discs)
      discs.push_back({{"joint", d.joint},
                       {"axial_n", d.axial_n},
                       {"lateral_moment_nmm", d.lateral_moment_nmm},
                       {"concave_mpa", d.concave_mpa},
                       {"convex_mpa", d.convex_mpa}});
    cases.push_back({{"type", c.curve.type},
                     {"cobb_deg", c.curve.cobb_deg},
                     {"upper_end", c.curve.upper_end},
                     {"apex", c.curve.apex},
                     {"lower_end", c.curve.lower_end},
                     {"convex", c.curve.convex_right ? "right" : "left"},
                     {"posed", c.refusal.empty()},
                     {"refusal", c.refusal},
                     {"apex_offset_mm", c.apex_offset_mm},
                     {"apical_concave_mpa", c.apical_concave_mpa},
                     {"apical_convex_mpa", c.apical_convex_mpa},
                     {"most_asymmetric_disc", c.most_asymmetric},
                     {"unloaded_apical_mpa", c.unloaded_apical_mpa},
                     {"discs", discs}});
  }
  for (const auto& x : s.findings)
    found.push_back({{"source", x.source},
                     {"finding", x.finding},
                     {"model", x.model},
                     {"verdict", x.match ? "MATCH" : "DIFFERS"}});
  return {{"study", "scoliosis"},
          {"subject", subject_json(s.subject)},
          {"cases", cases},
          {"findings", found},
          {"seconds", s.seconds}};
}

}  // namespace spinesim::studies
