// `spinesim study rib-cage` (rib_cage_study.hpp).
#include "spinesim/studies/rib_cage_study.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/spine/equilibrium.hpp"
#include "spinesim/spine/rib_cage.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>

namespace spinesim::studies {
namespace {

const char* const kAxes[3] = {"flexion/extension", "lateral bending", "axial rotation"};
/// The model's axis (x flexion, y torsion, z lateral bending) of each reported direction.
constexpr int kModelAxis[3] = {0, 2, 1};

struct InVitro {
  const char* study;
  const char* conditions;
  const char* removed;
  double growth_pct[3];  // FE, LB, AR
};
const InVitro kInVitro[] = {
    {"Liebsch et al. 2017", "6 specimens, ±2 N·m", "anterior rib cage", {52.2, 42.0, 94.4}},
    {"Mannen et al. 2018",
     "8 specimens, ±5 N·m, 400 N follower load",
     "whole rib cage",
     {63.0, 63.5, 58.8}},
};

/// The thoracic spine alone, T12 held: the in-vitro specimen.
spine::SpineModel specimen(const std::string& data_dir, spine::ModelOptions o,
                           const RibCageCase& c) {
  o.gravity = o.muscles = o.iap = o.trunk_muscles = false;
  o.rib_cage = c.cage;
  o.fused_joints.clear();
  for (int j = spine::joint_index("T12-L1"); j < int(spine::joint_names().size()); ++j)
    o.fused_joints.push_back(j);
  spine::SpineModel m = spine::load_spine_model(data_dir, o);
  if (c.cage && (!c.cartilage || c.cartilage_scale != 1 || c.costovertebral_scale != 1)) {
    spine::RibCageParts parts;
    parts.cartilage = c.cartilage;
    parts.cartilage_scale = c.cartilage_scale;
    parts.costovertebral_scale = c.costovertebral_scale;
    m.rib_cage = std::make_shared<const spine::RibCage>(
        spine::build_rib_cage(data_dir, m.vertebrae, m.scale.length, parts));
  }
  return m;
}

std::array<double, 3> ranges_of_motion(const spine::SpineModel& m, double moment_nmm) {
  spine::SolveOptions o;
  o.recruit = false;
  o.warn_above_600n = false;
  const int t1 = spine::vertebra_index("T1");
  std::array<double, 3> rom{};
  for (int a = 0; a < 3; ++a) {
    double turn[2];
    for (int k = 0; k < 2; ++k) {
      spine::ExternalLoad l;
      l.vertebra = t1;
      l.moment_nmm[kModelAxis[a]] = k == 0 ? moment_nmm : -moment_nmm;
      turn[k] = spine::solve_spine(m, {l}, o).displacement(t1, 3 + kModelAxis[a]);
    }
    rom[std::size_t(a)] = std::abs(turn[0] - turn[1]);
  }
  return rom;
}

RibCageScene scene(const std::string& data_dir, spine::ModelOptions o, const std::string& name,
                   double forward_n) {
  RibCageScene s;
  s.name = name;
  spine::SolveOptions so;
  so.warn_above_600n = false;
  const int t1 = spine::vertebra_index("T1"), t12 = spine::vertebra_index("T12");
  const std::size_t l4l5 = std::size_t(spine::joint_index("L4-L5"));
  for (int k = 0; k < 2; ++k) {
    o.rib_cage = k == 1;
    const spine::SpineModel m = spine::load_spine_model(data_dir, o);
    std::vector<spine::ExternalLoad> loads;
    if (forward_n != 0) {
      spine::ExternalLoad l;
      l.vertebra = t1;
      l.force_n.z() = forward_n;
      loads.push_back(l);
    }
    const spine::SpineSolution r = spine::solve_spine(m, loads, so);
    // Flexion about the model's x axis; the rotations are a few degrees, so the difference of
    // the two rotation vectors' x components is the relative rotation to well under 1 %.
    s.thoracic_flexion_deg[k] = r.displacement(t1, 3) - r.displacement(t12, 3);
    s.t1_translation_mm[k] = r.displacement.row(t1).head<3>().norm();
    s.l4l5_axial_n[k] = r.joints[l4l5].axial_n;
  }
  return s;
}

}  // namespace

RibCageStudy run_rib_cage_study(const std::string& data_dir, double moment_nm,
                                const spine::ModelOptions& model, const StageHooks& hooks) {
  if (!std::isfinite(moment_nm) || moment_nm < 0.1 || moment_nm > 20)
    throw std::invalid_argument("rib-cage study: the moment must lie within 0.1 … 20 N·m");
  Timer timer;
  RibCageStudy s;
  s.moment_nm = moment_nm;
  s.subject = spine::resolve_subject(data_dir, model.subject);
  auto make = [](const char* name, bool cage, bool cartilage, double cs, double cv) {
    RibCageCase c;
    c.name = name;
    c.cage = cage;
    c.cartilage = cartilage;
    c.cartilage_scale = cs;
    c.costovertebral_scale = cv;
    return c;
  };
  s.cases = {make("no cage", false, false, 1, 1),
             make("ribs on their heads (no cartilage)", true, false, 1, 1),
             make("whole cage", true, true, 1, 1),
             make("whole cage, cartilage x0.25", true, true, 0.25, 1),
             make("whole cage, cartilage x4", true, true, 4, 1),
             make("whole cage, costovertebral x4", true, true, 1, 4),
             make("whole cage, both x4", true, true, 4, 4)};
  for (RibCageCase& c : s.cases) {
    hooks.begin_stage("rib cage: " + c.name + ", ±" + fixed(moment_nm, 1) + " N·m on T1");
    c.rom_deg = ranges_of_motion(specimen(data_dir, model, c), moment_nm * 1000);
    for (int a = 0; a < 3; ++a)
      c.growth_pct[std::size_t(a)] =
          100 * (s.cases.front().rom_deg[std::size_t(a)] / c.rom_deg[std::size_t(a)] - 1);
    hooks.end_stage();
  }
  hooks.begin_stage("rib cage: standing and 300 N forward on T1, with and without");
  s.scenes = {scene(data_dir, model, "standing (gravity only)", 0),
              scene(data_dir, model, "300 N forward on T1", 300)};
  hooks.end_stage();
  s.seconds = timer.seconds();
  return s;
}

void print_rib_cage_study(std::ostream& os, const RibCageStudy& s, bool markdown) {
  os << "Thoracic spine T1-T12 (T12 held, no gravity or muscles), ±" << fixed(s.moment_nm, 1)
     << " N·m on T1; range of motion (deg) and how much it grows when the cage is removed\n\n";
  TextTable t({"case", "FE ROM", "LB ROM", "AR ROM", "FE growth", "LB growth", "AR growth"}, 1);
  for (const auto& c : s.cases) {
    std::vector<std::string> row{c.name};
    for (double r : c.rom_deg) row.push_back(fixed(r, 2));
    for (double g : c.growth_pct) row.push_back(&c == &s.cases.front() ? "-" : fixed(g, 1) + " %");
    t.add(row);
  }
  for (const auto& v : kInVitro) {
    std::vector<std::string> row{
        std::string("in vitro: ") + v.study + ", " + v.removed + " removed", "", "", ""};
    for (double g : v.growth_pct) row.push_back(fixed(g, 1) + " %");
    t.add(row);
  }
  t.print(os, markdown);
  os << "\n  In vitro: ";
  for (const auto& v : kInVitro) os << v.study << " (" << v.conditions << "); ";
  os << "the model's joints are linear\n  springs, so its growth barely depends on the moment.\n"
        "  The cage's springs: costovertebral complexes from Lebschy et al. 2024 (the model's "
        "rib heads);\n  costal cartilage an assumption (data/spine/rib_cage.json). No "
        "intercostal muscles or membranes.\n\n";
  os << "Whole spine, muscles recruited: the cage's effect on the thorax and on L4-L5\n\n";
  TextTable u({"scene", "T1-T12 flexion without (deg)", "with (deg)", "T1 |t| without (mm)",
               "with (mm)", "L4-L5 axial without (N)", "with (N)"},
              1);
  for (const auto& c : s.scenes)
    u.add({c.name, fixed(c.thoracic_flexion_deg[0], 2), fixed(c.thoracic_flexion_deg[1], 2),
           fixed(c.t1_translation_mm[0], 2), fixed(c.t1_translation_mm[1], 2),
           fixed(c.l4l5_axial_n[0], 1), fixed(c.l4l5_axial_n[1], 1)});
  u.print(os, markdown);
  os << "\n  T1 moves as the lumbar spine turns and the thorax bends; a stiffer thorax bends less, "
        "so the two\n  cancel less and |t| can grow while the flexion falls.\n";
  os << "\n  Body: " << subject_text(s.subject) << ". " << fixed(s.seconds, 1) << " s.\n";
}

nlohmann::json rib_cage_study_json(const RibCageStudy& s) {
  nlohmann::json cases = nlohmann::json::array(), vitro = nlohmann::json::array(),
                 scenes = nlohmann::json::array();
  for (const auto& c : s.cases)
    cases.push_back({{"case", c.name},
                     {"cage", c.cage},
                     {"cartilage", c.cartilage},
                     {"cartilage_scale", c.cartilage_scale},
                     {"costovertebral_scale", c.costovertebral_scale},
                     {"rom_deg",
                      {{"flexion_extension", c.rom_deg[0]},
                       {"lateral_bending", c.rom_deg[1]},
                       {"axial_rotation", c.rom_deg[2]}}},
                     {"growth_when_removed_pct",
                      {{"flexion_extension", c.growth_pct[0]},
                       {"lateral_bending", c.growth_pct[1]},
                       {"axial_rotation", c.growth_pct[2]}}}});
  for (const auto& v : kInVitro)
    vitro.push_back({{"study", v.study},
                     {"conditions", v.conditions},
                     {"removed", v.removed},
                     {"growth_when_removed_pct",
                      {{"flexion_extension", v.growth_pct[0]},
                       {"lateral_bending", v.growth_pct[1]},
                       {"axial_rotation", v.growth_pct[2]}}}});
  for (const auto& c : s.scenes)
    scenes.push_back(
        {{"scene", c.name},
         {"thoracic_flexion_deg",
          {{"without", c.thoracic_flexion_deg[0]}, {"with", c.thoracic_flexion_deg[1]}}},
         {"t1_translation_mm",
          {{"without", c.t1_translation_mm[0]}, {"with", c.t1_translation_mm[1]}}},
         {"l4l5_axial_n", {{"without", c.l4l5_axial_n[0]}, {"with", c.l4l5_axial_n[1]}}}});
  return {{"study", "rib-cage"}, {"moment_nm", s.moment_nm}, {"subject", subject_json(s.subject)},
          {"cases", cases},      {"in_vitro", vitro},        {"scenes", scenes},
          {"seconds", s.seconds}};
}

}  // namespace spinesim::studies
