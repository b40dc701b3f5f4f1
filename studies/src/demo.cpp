#include "spinesim/studies/demo.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/studies/haptic_plane_study.hpp"
#include "spinesim/studies/haptics_run.hpp"

#include "spinesim/calibration/compare.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/disc_level.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/studies/calibration_summary.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/data.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/materials_study.hpp"
#include "spinesim/studies/mesh_report.hpp"
#include "spinesim/studies/probe_study.hpp"
#include "spinesim/studies/spine_studies.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iterator>
#include <memory>
#include <sstream>
#include <vector>

namespace spinesim::studies {

namespace {
namespace fs = std::filesystem;

constexpr const char* kPresets[] = {"real-disc", "annulus-nucleus", "fibre-reinforced", "rubber",
                                    "polyethylene"};
constexpr double kSpineStudyForceN = 300;  // the spine studies' default force on T1

/// The four training and four held-out cases of the demo's calibration.
CalibrationRequest demo_calibration_request() {
  CalibrationRequest rq;
  for (const char* c : {"compression", "shear-ap", "flexion", "torsion"})
    rq.train.push_back(fem::load_case(c));
  for (const char* c : {"tension", "shear-lat", "extension", "lateral-bending"})
    rq.holdout.push_back(fem::load_case(c));
  return rq;
}

/// The demo's state, step by step (the order of the members is the order of the steps).
class Demo {
 public:
  Demo(const DemoRequest& rq, const StageHooks& hooks) : rq(rq), hooks(hooks) {}

  void mesh_disc();
  void fem_reference();
  void fem_load_cases();
  void material_study();
  void mss_baseline();
  void probe_test();
  void calibration();
  void spine_studies();
  void haptics();
  std::string report() const;
  std::string haptics_section() const;
  nlohmann::json summary(const std::string& report_path) const;

 private:
  const DemoRequest& rq;
  const StageHooks& hooks;
  mesh::DiscDimensions dims;
  mesh::TetMesh m;
  mesh::QualityReport quality;
  std::string mesh_path, result_path;
  double mesh_seconds = 0;
  mesh::RegionMaterials real_disc;
  std::unique_ptr<fem::DiscFem> solver;
  fem::Matrix6d k6 = fem::Matrix6d::Zero();
  double fem_seconds = 0;
  nlohmann::json cases = nlohmann::json::array();
  std::string case_table;
  MaterialsStudyOptions materials_options;
  std::vector<MaterialResult> materials;
  std::string constants_table, material_table;
  double materials_seconds = 0;
  MssFemComparison mss_vs_fem;
  ProbeStudyResult probe;
  std::string mss_table;
  double mss_seconds = 0;
  CalibrationRequest calibration_request = demo_calibration_request();
  CalibrationOutcome calibrated;
  std::string calibration_text;
  double calibration_seconds = 0;
  ValidationStudy spine_validation;
  FusionStudy spine_fusion;
  TrendsStudy spine_trends;
  std::string validation_text, fusion_text, trends_text;
  HapticPlaneResult haptic_plane;
  HapticsRunResult haptic_run;
  std::string haptic_plane_path, haptic_record_path;
};

// 1. Mesh the level between its vertebrae.
void Demo::mesh_disc() {
  dims = mesh::disc_dimensions(rq.level, data_dir());
  hooks.begin_stage("meshing the " + dims.level + " disc");
  const Timer t;
  m = mesh::mesh_disc_level(rq.level, rq.cell_size_mm, data_dir());
  mesh_seconds = t.seconds();
  hooks.end_stage(std::to_string(m.num_tets()) + " tets");
  quality = mesh::quality_report(m, mesh::parametric_disc_volume(dims));
  mesh_path = (fs::path(rq.out) / ("disc-" + dims.level + ".vtu")).string();
  mesh::write_vtu(mesh_path, m);
}

// 2. FEM reference with the real-disc material: the 6x6 stiffness.
void Demo::fem_reference() {
  real_disc = mesh::load_material("real-disc", data_dir());
  hooks.begin_stage("FEM P" + std::to_string(rq.fem_order) + " stiffness (real-disc)");
  const Timer t;
  solver = std::make_unique<fem::DiscFem>(m, real_disc, rq.fem_order,
                                          fem::DiscFem::default_plate_center(m));
  k6 = solver->stiffness_6x6();
  fem_seconds = t.seconds();
  hooks.end_stage(std::to_string(solver->num_dofs()) + " DOF");
}

// 2b. The eight named load cases: JSON rows, the markdown table, a VTU with every displacement.
void Demo::fem_load_cases() {
  hooks.begin_stage("FEM load cases");
  std::vector<mesh::DataArray> fields;
  TextTable table({"case", "load (disc frame)", "plate translation (mm, disc frame)",
                   "plate rotation (deg, disc frame)", "max |u| (mm)"});
  table.set_plain_markdown(true);
  for (const auto& c : fem::standard_load_cases()) {
    const auto sol = solver->solve_wrench(fem::global_wrench(c, m.frame));
    fields.push_back({"displacement_" + c.name, sol.displacement_mm});
    const Eigen::Vector3d t_local = m.frame.axes.transpose() * sol.plate_motion.head<3>();
    const Eigen::Vector3d r_local =
        m.frame.axes.transpose() * sol.plate_motion.tail<3>() * kDegPerRad;
    const double umax = sol.displacement_mm.rowwise().norm().maxCoeff();
    cases.push_back({{"name", c.name},
                     {"wrench_local", to_json(c.wrench_local)},
                     {"plate_translation_local_mm", to_json(t_local)},
                     {"plate_rotation_local_deg", to_json(r_local)},
                     {"reaction_wrench", to_json(sol.reaction_wrench)},
                     {"max_displacement_mm", umax}});
    static const char* component[] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
    Eigen::Index k = 0;
    c.wrench_local.cwiseAbs().maxCoeff(&k);
    const auto cell = [](const auto& v) {  // Eigen's own row layout, 4 significant digits
      std::ostringstream os;
      os << std::setprecision(4) << v;
      return os.str();
    };
    std::ostringstream load;  // default precision, as the case is defined
    load << component[k] << " = " << c.wrench_local(k) << (k < 3 ? " N" : " N·mm");
    table.add(
        {c.name, load.str(), cell(t_local.transpose()), cell(r_local.transpose()), cell(umax)});
  }
  std::ostringstream os;
  table.print(os, true);
  case_table = os.str();
  result_path = (fs::path(rq.out) / ("fem-" + dims.level + ".vtu")).string();
  mesh::write_vtu(result_path, m, fields);
  hooks.end_stage(std::to_string(fields.size()) + " cases");
}

// 3. Material study: FEM, untuned and calibrated MSS per preset, on the same mesh.
void Demo::material_study() {
  materials_options.fem_order = rq.fem_order;
  const Timer t;
  TextTable constants({"material", "constants", "density (kg/m³)"});
  constants.set_plain_markdown(true);
  for (const char* name : kPresets) {
    const auto mat = mesh::load_material(name, data_dir());
    constants.add({mat.name, describe_material(mat),
                   significant(mat.at(int(mesh::Region::annulus)).density_kg_m3, 6)});
    materials.push_back(study_material(m, mat, materials_options, hooks));
  }
  materials_seconds = t.seconds();
  std::ostringstream ct, mt;
  constants.print(ct, true);
  print_materials(mt, materials, rq.fem_order, true);
  constants_table = ct.str();
  material_table = mt.str();
}

// 4. Mass-spring disc (untuned Van Gelder constants) vs the FEM above: the baseline.
void Demo::mss_baseline() {
  hooks.begin_stage("MSS vs FEM, " + std::to_string(fem::standard_load_cases().size()) +
                    " load cases");
  const Timer t;
  const mss::MssModel mss_model(m, real_disc);
  mss_vs_fem =
      calibration::compare_mss_fem(*solver, mss_model, fem::standard_load_cases(), real_disc.name);
  mss_seconds = t.seconds();
  hooks.end_stage();
  std::ostringstream os;
  print_comparison(os, mss_vs_fem, true);
  mss_table = os.str();
}

// 4b. Thesis 5.3, test 1 (fig. 5.8): a rigid sphere pressed into the wall of the untuned disc,
//     force and disc volume tracked (probe_study.hpp); its CSV feeds the report's plot.
void Demo::probe_test() {
  ProbeStudyRequest r;
  r.stepping.out = (fs::path(rq.out) / "probe").string();
  r.stepping.frame_every = 250;  // a few VTU frames for ParaView; the plot uses the CSV
  probe = run_probe_study(m, real_disc, r, hooks);
  if (probe.stats.diverged)
    throw std::runtime_error("demo: the probe test diverged: " + probe.stats.message);
}

// 5. The calibration protocol on the real disc: train on four cases, hold out four, untuned
//    beside tuned (nonlinear check in the linear regime), as `spinesim calibrate`.
void Demo::calibration() {
  hooks.begin_stage("calibration of the real disc (Ipopt), trained and held-out cases");
  const Timer t;
  calibrated = calibrate_disc(m, real_disc, calibration_request);
  calibration_seconds = t.seconds();
  hooks.end_stage(calibrated.result.status);
  std::ostringstream os;
  print_calibration(os, calibrated, calibration_request);
  calibration_text = os.str();
}

// 6. The spine: validation (thesis 3.4), fusion (6.1), trends (6.3-6.4), on the default model.
void Demo::spine_studies() {
  spine_validation = run_validation_study(data_dir(), {}, hooks);
  spine_fusion = run_fusion_study(data_dir(), kSpineStudyForceN, {}, hooks);
  spine_trends = run_trends_study(data_dir(), kSpineStudyForceN, {}, hooks);
  std::ostringstream v, f, t;
  print_validation(v, spine_validation, true);
  print_fusion(f, spine_fusion, true);
  print_trends(t, spine_trends, true);
  validation_text = v.str(), fusion_text = f.str(), trends_text = t.str();
  // The per-run numbers behind the findings, for the report's plots (scripts/report.py).
  write_csv_file((fs::path(rq.out) / "spine_fusion.csv").string(), fusion_csv(spine_fusion));
  write_csv_file((fs::path(rq.out) / "spine_trends.csv").string(), trends_csv(spine_trends));
}

// 7. The haptic loop: the thesis's plane test of the Gao-Gibson force, and the simulated hand
//    stroking down the spinous processes of the whole spine at 1 kHz (the proxy renderer).
void Demo::haptics() {
  hooks.begin_stage("haptic plane test (Gao-Gibson eqs 4.9, 4.10)");
  haptic_plane = run_haptic_plane_study(HapticPlaneRequest());
  haptic_plane_path = (fs::path(rq.out) / "haptic_plane.csv").string();
  write_csv_file(haptic_plane_path, haptic_plane_csv(haptic_plane));
  hooks.end_stage(std::to_string(haptic_plane.rows.size()) + " depths");
  hooks.begin_stage("haptic loop: simulated hand strokes the spine's spinous processes");
  HapticsRunRequest request;
  request.record = (fs::path(rq.out) / "haptics_stroke.csv").string();
  haptic_record_path = request.record;
  haptic_run = run_haptics(request, data_dir());
  hooks.end_stage(std::to_string(haptic_run.stats.ticks) + " ticks");
}

// 8. The report.
std::string Demo::report() const {
  const fem::Matrix6d k_local = fem::to_disc_frame(k6, m.frame);
  std::ostringstream report;
  report << "# spinesim demo — " << dims.level << " disc\n\n"
         << "## Mesh (CGAL Mesh_3, cell size " << rq.cell_size_mm << " mm)\n\n```\n";
  print_quality(report, quality, m.source);
  report << "```\n\nMeshing took " << std::setprecision(3) << mesh_seconds << " s. Files: `"
         << fs::path(mesh_path).filename().string() << "`, `"
         << fs::path(result_path).filename().string() << "` (open in ParaView).\n\n"
         << "## FEM reference (P" << rq.fem_order
         << ", real-disc E = " << real_disc.fallback.youngs_modulus_mpa
         << " MPa, nu = " << std::setprecision(3) << real_disc.fallback.poisson_ratio << ")\n\n"
         << solver->num_dofs() << " DOF; assembly + factorisation + 6x6 condensation "
         << std::setprecision(3) << fem_seconds
         << " s.\n\n### 6x6 disc stiffness in the disc frame (x lateral, y axial, z "
            "anterior)\n\n```\n";
  print_stiffness(report, k_local);
  report << std::defaultfloat << std::setprecision(4);  // the prose below: shortest form, 4 digits
  report << "```\n\n### Load cases (wrench on the superior plate, disc frame)\n\n"
         << case_table
         << "\n## Material comparison (thesis fig. 5.9): FEM, untuned and tuned MSS\n\n"
         << "The same mesh (cell size " << rq.cell_size_mm
         << " mm) in each material preset, side by side: the FEM P" << rq.fem_order
         << "\n(linear); the thesis's mass-spring disc with untuned Van Gelder constants; and the "
            "mass-spring\n"
         << "disc calibrated to that material's FEM (" << term_set_name(materials_options.terms)
         << " stiffness scales per region; Ipopt on compression,\nshear-ap, flexion and torsion). "
         << "The thesis's fig. 5.9 load, 500 N compression on the superior plate, is\nsolved "
            "statically "
         << "(the MSS nonlinear); stiffnesses are linear at rest. Disc frame: x lateral, y axial,\n"
         << "z anterior. `spinesim study materials --help` gives the protocol. "
         << std::setprecision(3) << materials_seconds << " s.\n\n"
         << constants_table << "\n"
         << material_table << "\n## MSS vs FEM (untuned Van Gelder baseline)\n\n"
         << "The thesis's mass-spring disc (main, radial and torsional springs, real-disc "
            "constants) on the same\n"
         << "mesh, static, against the FEM above (`spinesim mss compare --help` gives the "
            "protocol): displacement\n"
         << "error under each case's wrench, reaction error under the FEM's plate motion. This is "
            "what the\n"
         << "calibration must beat. " << std::setprecision(3) << mss_seconds << " s.\n\n"
         << mss_table << "\n## Calibration: the mass-spring disc tuned to the FEM (real disc)\n\n"
         << "Ipopt fits the per-region scales of the MSS terms ("
         << term_set_name(calibration_request.terms)
         << ") to the FEM on four training cases; the other four are held out.\nErrors: relative "
            "nodal "
         << "displacement, nonlinear MSS at the case loads x "
         << calibration_request.check_load_scale
         << " (the linear regime the FEM describes),\nthe linearised errors in brackets. `spinesim "
            "calibrate --help` "
         << "and calibration/README.md give the protocol. " << std::setprecision(3)
         << calibration_seconds << " s.\n\n```\n"
         << calibration_text << "```\n"
         << "\n## Spine: validation (thesis 3.4)\n\n"
         << "The open thoracolumbar spine (spine/: 17 vertebrae, F.4 joint springs with F.5 "
            "limits, ligaments, the\n"
         << "F.8-F.19 lumbar muscles and the LifeMOD trunk muscles the thesis names without data "
            "(restored in\n"
         << "data/spine/trunk_muscles.csv by stated rules), recruited by Ipopt, the IAP bushing, "
            "gravity), nothing tuned\n"
         << "to these targets. "
         << "`spinesim study validation --help` gives the protocol. " << std::setprecision(3)
         << spine_validation.seconds << " s.\n\n"
         << validation_text << "\n## Spine: fusion vs the normal spine (thesis 6.1)\n\n"
         << "`spinesim study fusion --help` gives the protocol. " << std::setprecision(3)
         << spine_fusion.seconds << " s.\n\n"
         << fusion_text
         << "\n## Spine: relative vertebra motion under a force on T1 vs the thesis's trends "
            "(6.3-6.4)\n\n"
         << "`spinesim study trends --help` gives the protocol. " << std::setprecision(3)
         << spine_trends.seconds << " s.\n\n"
         << trends_text << haptics_section();
  return report.str();
}

// The report's haptics section.
std::string Demo::haptics_section() const {
  std::ostringstream os;
  os << std::defaultfloat
     << "\n## Haptics: the Gao-Gibson plane test (thesis 4.4.2, figs 4.16-4.19)\n\n"
     << "`spinesim study haptic-plane --help` gives the protocol; the force-depth curves are in `"
     << fs::path(haptic_plane_path).filename().string() << "`.\n\n```\n"
     << haptic_plane_table(haptic_plane) << "```\n"
     << "\n## Haptics: the 1 kHz loop on the whole spine\n\n"
     << "A simulated hand (mass-spring-damper on the script's set-point) strokes down the "
        "spinous processes\nT1-L5 with a 4 mm probe; the sphere proxy renders the 18 "
        "parametric bodies. Every tick is in `"
     << fs::path(haptic_record_path).filename().string()
     << "` (replay it with\n`spinesim haptics run --device replay --replay FILE`).\n\n```\n"
     << haptics_run_table(haptic_run) << "```\n";
  return os.str();
}

nlohmann::json Demo::summary(const std::string& report_path) const {
  const fem::Matrix6d k_local = fem::to_disc_frame(k6, m.frame);
  return {{"level", dims.level},
          {"mesh", quality_json(quality)},
          {"mesh_seconds", mesh_seconds},
          {"fem_order", rq.fem_order},
          {"fem_dofs", solver->num_dofs()},
          {"fem_stiffness_seconds", fem_seconds},
          {"stiffness_6x6_disc_frame", matrix_to_json(stiffness_per_degree(k_local))},
          {"stiffness_6x6_units", kStiffnessUnits},
          {"cases", cases},
          {"materials", materials_json(materials)},
          {"materials_seconds", materials_seconds},
          {"mss_vs_fem", comparison_json(mss_vs_fem)},
          {"probe_test", probe.summary},
          {"calibration", calibrated.tuned.report},
          {"calibration_scales", calibrated.tuned.scales},
          {"spine_validation", validation_json(spine_validation)},
          {"spine_fusion", fusion_json(spine_fusion)},
          {"spine_trends", trends_json(spine_trends)},
          {"haptic_plane", haptic_plane_json(haptic_plane)},
          {"haptics_run", haptics_run_json(haptic_run)},
          {"report", report_path},
          {"files", {mesh_path, result_path}}};
}

}  // namespace

int demo_stages() {
  return 12 + kStagesPerMaterial * int(std::size(kPresets)) + kValidationStages + kFusionStages +
         kTrendsStages;
}

namespace {

/// A number at `pointer` in `j` ("n/a" when absent), with `digits` significant digits.
std::string at(const nlohmann::json& j, const std::string& pointer, int digits = 4) {
  const nlohmann::json::json_pointer p(pointer);
  if (!j.contains(p) || !j.at(p).is_number()) return "n/a";
  const double v = j.at(p).get<double>();
  // Counts (tets, DOF, ticks) in full; measured numbers to `digits` significant digits.
  if (j.at(p).is_number_integer() ||
      (v == std::round(v) && std::abs(v) >= 1e3 && std::abs(v) < 1e15))
    return fixed(std::round(v), 0);
  return significant(v, digits);
}

/// Mean of `key` over the rows of `rows` (NaN when none).
double mean_of(const nlohmann::json& rows, const char* key) {
  double sum = 0;
  int n = 0;
  for (const auto& r : rows)
    if (r.contains(key) && r.at(key).is_number()) sum += r.at(key).get<double>(), ++n;
  return n ? sum / n : std::nan("");
}

}  // namespace

std::string demo_summary(const DemoResult& r) {
  const nlohmann::json& s = r.summary;
  const nlohmann::json holdout = s.contains("calibration")
                                     ? s["calibration"].value("holdout", nlohmann::json::array())
                                     : nlohmann::json::array();
  std::ostringstream os;
  os << "spinesim demo: " << s.value("level", std::string("?")) << "\n"
     << "  mesh         " << at(s, "/mesh/tets") << " tets, " << at(s, "/mesh/nodes")
     << " nodes, min dihedral " << at(s, "/mesh/min_dihedral_deg", 3) << " deg\n"
     << "  FEM P" << at(s, "/fem_order", 1) << "       " << at(s, "/fem_dofs")
     << " DOF, axial stiffness " << at(s, "/stiffness_6x6_disc_frame/1/1") << " N/mm\n"
     << "  MSS vs FEM   held-out displacement error untuned "
     << percent(mean_of(holdout, "untuned_error")) << ", tuned "
     << percent(mean_of(holdout, "tuned_error")) << " (mean of " << holdout.size() << " cases)\n"
     << "  spine        L5-S1 " << at(s, "/spine_validation/mcgill/axial_n")
     << " N (McGill & Norman), L4-L5 " << at(s, "/spine_validation/wilke/axial_n")
     << " N (Wilke: " << at(s, "/spine_validation/wilke/target/axial_n") << " N)\n"
     << "  haptics      " << at(s, "/haptics_run/rate_hz") << " Hz, "
     << at(s, "/haptics_run/missed_deadlines") << " missed deadlines of "
     << at(s, "/haptics_run/ticks", 6) << " ticks\n"
     << "Report: " << r.report_path << " (markdown), summary.json beside it\n"
     << (r.html.written ? "" : "note: ") << r.html.message << "\n";
  return os.str();
}

DemoResult run_demo(const DemoRequest& rq, const StageHooks& hooks) {
  if (rq.fem_order != 1 && rq.fem_order != 2)
    throw std::invalid_argument("the FEM order must be 1 or 2");
  prepare_output_folder(rq.out, "--out");
  Demo demo(rq, hooks);
  demo.mesh_disc();
  demo.fem_reference();
  demo.fem_load_cases();
  demo.material_study();
  demo.mss_baseline();
  demo.probe_test();
  demo.calibration();
  demo.spine_studies();
  demo.haptics();
  DemoResult r;
  r.report_markdown = demo.report();
  r.report_path = (fs::path(rq.out) / "report.md").string();
  write_text_file(r.report_path, r.report_markdown + markdown_provenance());
  r.summary = demo.summary(r.report_path);
  write_json_file((fs::path(rq.out) / "summary.json").string(), r.summary);
  hooks.begin_stage("viewer screenshots");
  r.viewer_note = rq.viewer_screenshots ? rq.viewer_screenshots(rq.out) : "not asked for";
  hooks.end_stage(r.viewer_note);
  hooks.begin_stage("plots and report.html");
  r.html = write_html_report(rq.out);
  hooks.end_stage(r.html.written ? "written" : "not written");
  return r;
}

}  // namespace spinesim::studies
