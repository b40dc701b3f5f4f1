// spinesim demo — the pipeline on embedded defaults, with a report a person can read.
//
//   spinesim demo [--out demo-out]
//
// Steps: 1. mesh the L4-L5 disc between its vertebrae (thesis tables F.1/F.2 placement);
// 2. FEM reference (real-disc material): the 6x6 disc stiffness and the eight named load
// cases; 3. the material study (materials_study.hpp, thesis fig. 5.9): per material preset the
// FEM, the untuned and the calibrated mass-spring disc under 500 N compression; 4. the
// mass-spring disc with the untuned Van Gelder constants against that FEM on all eight cases
// (mss_report.hpp protocol); 5. the calibration protocol (calibration_report.hpp): Ipopt on four
// training cases, four held out, untuned beside tuned; 6. the spine (spine_studies.hpp): the
// validation cases of thesis 3.4 beside their targets, fusion vs the normal spine (6.1) and the
// relative vertebra motions under a force on T1 against the thesis's trends (6.3-6.4); 7. write
// VTU results, report.md and summary.json into --out.
#include "spinesim/studies/calibration_report.hpp"
#include "cli_common.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/studies/fem_report.hpp"
#include "spinesim/studies/materials_study.hpp"
#include "spinesim/studies/mesh_report.hpp"
#include "model_flags.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/spine_studies.hpp"

#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"
#include "spinesim/mss/model.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <vector>

namespace spinesim::cli {
namespace {

struct DemoArgs {
  std::string out = "demo-out", level = "L4-L5";
  double cell_size_mm = mesh::MeshOptions().cell_size_mm;
  int order = 2;
  bool json = false, quiet = false;
};

/// Block rotation of a 6x6 wrench/motion matrix into the disc frame: K_local = R^T K R.
fem::Matrix6d to_disc_frame(const fem::Matrix6d& k, const mesh::DiscFrame& f) {
  fem::Matrix6d r = fem::Matrix6d::Zero();
  r.topLeftCorner<3, 3>() = f.axes;
  r.bottomRightCorner<3, 3>() = f.axes;
  return r.transpose() * k * r;
}

void run_demo(const DemoArgs& a) {
  namespace fs = std::filesystem;
  fs::create_directories(a.out);
  static const char* kPresets[] = {"real-disc", "annulus-nucleus", "rubber", "polyethylene"};
  Progress progress(5 + kStagesPerMaterial * int(std::size(kPresets)) + kValidationStages + kFusionStages + kTrendsStages,
                    a.quiet || a.json);

  // 1. Mesh.
  const auto dims = mesh::disc_dimensions(a.level, data_dir());
  const auto frame = mesh::disc_frame_in_spine(dims.level, data_dir());
  mesh::MeshOptions opt;
  opt.cell_size_mm = a.cell_size_mm;
  progress.begin("meshing the " + dims.level + " disc");
  const mesh::TetMesh m = mesh::mesh_parametric_disc(dims, opt, frame);
  const double mesh_s = progress.end(std::to_string(m.num_tets()) + " tets");
  const auto quality = mesh::quality_report(m, mesh::parametric_disc_volume(dims));
  const std::string mesh_path = (fs::path(a.out) / ("disc-" + dims.level + ".vtu")).string();
  mesh::write_vtu(mesh_path, m);

  // 2. FEM reference with the real-disc material: stiffness and the named load cases.
  const auto real_disc = mesh::load_material("real-disc", data_dir());
  progress.begin("FEM P" + std::to_string(a.order) + " stiffness (real-disc)");
  const fem::DiscFem solver(m, real_disc, a.order, fem::DiscFem::default_plate_center(m));
  const fem::Matrix6d k6 = solver.stiffness_6x6();
  const double fem_s = progress.end(std::to_string(solver.num_dofs()) + " DOF");

  progress.begin("FEM load cases");
  std::vector<mesh::DataArray> fields;
  nlohmann::json cases = nlohmann::json::array();
  std::ostringstream case_table;
  case_table << "| case | load (disc frame) | plate translation (mm, disc frame) | plate rotation (deg, disc frame) | max |u| (mm) |\n"
             << "|---|---|---|---|---|\n";
  for (const auto& c : fem::standard_load_cases()) {
    const auto sol = solver.solve_wrench(fem::global_wrench(c, m.frame));
    fields.push_back({"displacement_" + c.name, sol.displacement_mm});
    const Eigen::Vector3d t_local = m.frame.axes.transpose() * sol.plate_motion.head<3>();
    const Eigen::Vector3d r_local = m.frame.axes.transpose() * sol.plate_motion.tail<3>() * 180.0 / M_PI;
    const double umax = sol.displacement_mm.rowwise().norm().maxCoeff();
    cases.push_back({{"name", c.name},
                     {"wrench_local", to_json(Eigen::VectorXd(c.wrench_local))},
                     {"plate_translation_local_mm", to_json(Eigen::VectorXd(t_local))},
                     {"plate_rotation_local_deg", to_json(Eigen::VectorXd(r_local))},
                     {"reaction_wrench", to_json(Eigen::VectorXd(sol.reaction_wrench))},
                     {"max_displacement_mm", umax}});
    static const char* component[] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};
    Eigen::Index k = 0;
    c.wrench_local.cwiseAbs().maxCoeff(&k);
    std::ostringstream load;
    load << component[k] << " = " << c.wrench_local(k) << (k < 3 ? " N" : " N·mm");
    case_table << std::setprecision(4) << "| " << c.name << " | " << load.str() << " | " << t_local.transpose()
               << " | " << r_local.transpose() << " | " << umax << " |\n";
  }
  const std::string result_path = (fs::path(a.out) / ("fem-" + dims.level + ".vtu")).string();
  mesh::write_vtu(result_path, m, fields);
  progress.end(std::to_string(fields.size()) + " cases");

  // 3. Material study: FEM, untuned and calibrated MSS per preset, on the same mesh.
  MaterialsStudyOptions study_options;
  study_options.fem_order = a.order;
  StageHooks hooks;
  hooks.begin = [&](const std::string& what) { progress.begin(what); };
  hooks.end = [&](const std::string& detail) { progress.end(detail); };
  const Timer t_study;
  std::vector<MaterialResult> study;
  std::ostringstream constants_table;
  constants_table << "| material | constants | density (kg/m³) |\n|---|---|---|\n";
  for (const char* name : kPresets) {
    const auto mat = mesh::load_material(name, data_dir());
    constants_table << "| " << mat.name << " | " << describe_material(mat) << " | "
                    << mat.at(int(mesh::Region::annulus)).density_kg_m3 << " |\n";
    study.push_back(study_material(m, mat, study_options, hooks));
  }
  const double study_s = t_study.seconds();
  std::ostringstream material_table;
  print_materials(material_table, study, a.order, true);

  // 4. Mass-spring disc (untuned Van Gelder constants) vs the FEM above: the baseline.
  progress.begin("MSS vs FEM, " + std::to_string(fem::standard_load_cases().size()) + " load cases");
  const mss::MssModel mss_model(m, real_disc);
  const MssFemComparison mss_vs_fem = calibration::compare_mss_fem(solver, mss_model, fem::standard_load_cases(), real_disc.name);
  const double mss_s = progress.end();
  std::ostringstream mss_table;
  print_comparison(mss_table, mss_vs_fem, true);

  // 5. The calibration protocol on the real disc: train on four cases, hold out four, untuned
  //    beside tuned (nonlinear check in the linear regime), as `spinesim calibrate`.
  progress.begin("calibration of the real disc (Ipopt), trained and held-out cases");
  const CalibrationRequest calibration_request = [] {
    CalibrationRequest rq;
    for (const char* c : {"compression", "shear-ap", "flexion", "torsion"}) rq.train.push_back(fem::load_case(c));
    for (const char* c : {"tension", "shear-lat", "extension", "lateral-bending"}) rq.holdout.push_back(fem::load_case(c));
    return rq;
  }();
  const CalibrationOutcome calibrated = calibrate_disc(m, real_disc, calibration_request);
  const double calibration_s = progress.end(calibrated.result.status);
  std::ostringstream calibration_text;
  print_calibration(calibration_text, calibrated, calibration_request);

  // 6. The spine: validation (thesis 3.4), fusion (6.1), trends (6.3-6.4), on the default model.
  StageHooks spine_hooks;
  spine_hooks.begin = [&](const std::string& what) { progress.begin(what); };
  spine_hooks.end = [&](const std::string& detail) { progress.end(detail); };
  constexpr double kSpineStudyForceN = 300;  // the studies' default force on T1
  const ValidationStudy spine_validation = run_validation_study(data_dir(), {}, spine_hooks);
  const FusionStudy spine_fusion = run_fusion_study(data_dir(), kSpineStudyForceN, {}, spine_hooks);
  const TrendsStudy spine_trends = run_trends_study(data_dir(), kSpineStudyForceN, {}, spine_hooks);
  std::ostringstream validation_text, fusion_text, trends_text;
  print_validation(validation_text, spine_validation, true);
  print_fusion(fusion_text, spine_fusion, true);
  print_trends(trends_text, spine_trends, true);

  // 7. Report.
  const fem::Matrix6d k_local = to_disc_frame(k6, m.frame);
  std::ostringstream report;
  report << "# spinesim demo — " << dims.level << " disc\n\n"
         << "## Mesh (CGAL Mesh_3, cell size " << opt.cell_size_mm << " mm)\n\n```\n";
  print_quality(report, quality, m.source);
  report << "```\n\nMeshing took " << std::setprecision(3) << mesh_s << " s. Files: `" << fs::path(mesh_path).filename().string()
         << "`, `" << fs::path(result_path).filename().string() << "` (open in ParaView).\n\n"
         << "## FEM reference (P" << a.order << ", real-disc E = " << real_disc.fallback.youngs_modulus_mpa
         << " MPa, nu = " << std::setprecision(3) << real_disc.fallback.poisson_ratio << ")\n\n"
         << solver.num_dofs() << " DOF; assembly + factorisation + 6x6 condensation " << std::setprecision(3) << fem_s
         << " s.\n\n### 6x6 disc stiffness in the disc frame (x lateral, y axial, z anterior)\n\n```\n";
  print_stiffness(report, k_local);
  report << "```\n\n### Load cases (wrench on the superior plate, disc frame)\n\n" << case_table.str()
         << "\n## Material comparison (thesis fig. 5.9): FEM, untuned and tuned MSS\n\n"
         << "The same mesh (cell size " << opt.cell_size_mm << " mm) in each material preset, side by side: the FEM P"
         << a.order << "\n(linear); the thesis's mass-spring disc with untuned Van Gelder constants; and the mass-spring\n"
         << "disc calibrated to that material's FEM (" << term_set_name(study_options.terms)
         << " stiffness scales per region; Ipopt on compression,\nshear-ap, flexion and torsion). "
         << "The thesis's fig. 5.9 load, 500 N compression on the superior plate, is\nsolved statically "
         << "(the MSS nonlinear); stiffnesses are linear at rest. Disc frame: x lateral, y axial,\n"
         << "z anterior. `spinesim study materials --help` gives the protocol. " << std::setprecision(3) << study_s
         << " s.\n\n"
         << constants_table.str() << "\n" << material_table.str()
         << "\n## MSS vs FEM (untuned Van Gelder baseline)\n\n"
         << "The thesis's mass-spring disc (main, radial and torsional springs, real-disc constants) on the same\n"
         << "mesh, static, against the FEM above (`spinesim mss compare --help` gives the protocol): displacement\n"
         << "error under each case's wrench, reaction error under the FEM's plate motion. This is what the\n"
         << "calibration must beat. " << std::setprecision(3) << mss_s << " s.\n\n"
         << mss_table.str()
         << "\n## Calibration: the mass-spring disc tuned to the FEM (real disc)\n\n"
         << "Ipopt fits the per-region scales of the MSS terms (" << term_set_name(calibration_request.terms)
         << ") to the FEM on four training cases; the other four are held out.\nErrors: relative nodal "
         << "displacement, nonlinear MSS at the case loads x " << calibration_request.check_load_scale
         << " (the linear regime the FEM describes),\nthe linearised errors in brackets. `spinesim calibrate --help` "
         << "and calibration/README.md give the protocol. " << std::setprecision(3) << calibration_s << " s.\n\n```\n"
         << calibration_text.str() << "```\n"
         << "\n## Spine: validation (thesis 3.4)\n\n"
         << "The open thoracolumbar spine (spine/: 17 vertebrae, F.4 joint springs with F.5 limits, ligaments, the\n"
         << "F.8-F.19 lumbar muscles and the LifeMOD trunk muscles the thesis names without data (restored in\n"
         << "data/spine/trunk_muscles.csv by stated rules), recruited by Ipopt, the IAP bushing, gravity), nothing tuned\n"
         << "to these targets. "
         << "`spinesim study validation --help` gives the protocol. " << std::setprecision(3) << spine_validation.seconds
         << " s.\n\n"
         << validation_text.str()
         << "\n## Spine: fusion vs the normal spine (thesis 6.1)\n\n"
         << "`spinesim study fusion --help` gives the protocol. " << std::setprecision(3) << spine_fusion.seconds << " s.\n\n"
         << fusion_text.str()
         << "\n## Spine: relative vertebra motion under a force on T1 vs the thesis's trends (6.3-6.4)\n\n"
         << "`spinesim study trends --help` gives the protocol. " << std::setprecision(3) << spine_trends.seconds << " s.\n\n"
         << trends_text.str();
  const std::string report_path = (fs::path(a.out) / "report.md").string();
  {
    std::ofstream f(report_path);
    f << report.str();
  }
  nlohmann::json j = {{"level", dims.level},
                      {"mesh", quality_json(quality)},
                      {"mesh_seconds", mesh_s},
                      {"fem_order", a.order},
                      {"fem_dofs", solver.num_dofs()},
                      {"fem_stiffness_seconds", fem_s},
                      {"stiffness_6x6_disc_frame", to_json(Eigen::MatrixXd(stiffness_per_degree(k_local)))},
                      {"stiffness_6x6_units", kStiffnessUnits},
                      {"cases", cases},
                      {"materials", materials_json(study)},
                      {"materials_seconds", study_s},
                      {"mss_vs_fem", comparison_json(mss_vs_fem)},
                      {"calibration", calibrated.tuned.report},
                      {"calibration_scales", calibrated.tuned.scales},
                      {"spine_validation", validation_json(spine_validation)},
                      {"spine_fusion", fusion_json(spine_fusion)},
                      {"spine_trends", trends_json(spine_trends)},
                      {"report", report_path},
                      {"files", {mesh_path, result_path}}};
  {
    std::ofstream f(fs::path(a.out) / "summary.json");
    f << j.dump(2) << "\n";
  }
  if (a.json)
    print_json(j);
  else
    std::cout << report.str() << "\nReport written to " << report_path << "\n";
}

}  // namespace

void register_demo(CLI::App& app) {
  auto a = std::make_shared<DemoArgs>();
  auto* cmd = app.add_subcommand("demo", "Run the pipeline on the embedded defaults and write a readable report");
  cmd->add_option("--out", a->out, "Output folder")->capture_default_str();
  cmd->add_option("--level", a->level, "Disc level")->capture_default_str();
  cmd->add_option("--cell-size", a->cell_size_mm, "Mesh cell size, mm")->capture_default_str();
  cmd->add_option("--order", a->order, "FEM element order 1 or 2")->capture_default_str();
  cmd->add_flag("--json", a->json, "Print a JSON summary on stdout");
  cmd->add_flag("--quiet", a->quiet, "No progress on stderr");
  cmd->callback([a] { run_demo(*a); });
}

}  // namespace spinesim::cli
