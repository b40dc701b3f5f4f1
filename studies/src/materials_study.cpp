#include "spinesim/studies/materials_study.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/stepped_study.hpp"
#include "spinesim/studies/toolkit.hpp"

#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mss/model.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace spinesim::studies {
namespace {

/// The training cases of the calibration (those of `spinesim calibrate`); every other case is
/// held out (reported in the tuned file, not fitted).
const char* kTrainCases = "compression,shear-ap,flexion,torsion";

/// 6x6 plate stiffness (global frame, rotations in rad) -> its disc-frame diagonal, N/mm and
/// N·mm/deg.
fem::Vector6d disc_frame_diagonal(const fem::Matrix6d& k, const mesh::DiscFrame& frame) {
  return fem::stiffness_per_degree(fem::to_disc_frame(k, frame)).diagonal();
}

/// Disc-frame axial (y) component of a global plate translation, mm.
double axial_translation(const fem::Vector6d& q, const mesh::DiscFrame& frame) {
  return (frame.axes.transpose() * q.head<3>())(1);
}

/// (V - V0)/V0 of the P1 mesh with its vertices moved by u (#V×3, mm).
double p1_volume_change(const mesh::TetMesh& m, const Eigen::MatrixX3d& u) {
  mesh::TetMesh deformed = m;
  deformed.V += u;
  const double v0 = mesh::mesh_volume(m);
  return (mesh::mesh_volume(deformed) - v0) / v0;
}

/// The MSS under the compression wrench (nonlinear static), compared with the FEM's solution.
ModelResponse mss_response(const mss::MssModel& model, const fem::Vector6d& wrench,
                           const Eigen::Vector3d& center, const fem::Matrix6d& k6,
                           const fem::PlateSolution& f) {
  const mesh::TetMesh& m = model.mesh();
  mss::Boundary bc;
  bc.plate_mode = mss::PlateMode::wrench;
  bc.wrench = wrench;
  bc.plate_center_mm = center;
  const mss::StaticResult s = mss::solve_static(model, bc);
  const Eigen::MatrixX3d u = mss::displacement(model, s.x_mm);
  ModelResponse r;
  r.stiffness_diagonal = disc_frame_diagonal(k6, m.frame);
  r.plate_axial_displacement_mm = axial_translation(s.plate_motion, m.frame);
  r.max_displacement_mm = u.rowwise().norm().maxCoeff();
  r.volume_change = mss::volume_change(model, s.x_mm);
  r.displacement_error = (u - f.displacement_mm).norm() / f.displacement_mm.norm();
  r.converged = s.converged;
  r.inverted_tets = model.inverted_tets(s.x_mm);
  r.newton_iterations = s.iterations;
  r.message = s.message;
  return r;
}

void hook(const std::function<void(const std::string&)>& h, const std::string& s) {
  if (h) h(s);
}

// --- formatting ------------------------------------------------------------------------------

/// `s` right-aligned (or left) in `width` columns, counting UTF-8 code points (· is one column).
std::string pad(const std::string& s, int width, bool left = false) {
  int cols = 0;
  for (unsigned char ch : s) cols += (ch & 0xC0) != 0x80;
  const std::string fill(std::size_t(std::max(0, width - cols)), ' ');
  return left ? s + fill : fill + s;
}

/// About four significant digits without an exponent (46222, 726.0, 0.06912): tables line up.
std::string number(double v) {
  std::ostringstream s;
  const double a = std::abs(v);
  if (a == 0 || a >= 1e7 || a < 1e-4)
    s << std::setprecision(4) << v;
  else
    s << std::fixed << std::setprecision(std::max(0, 3 - int(std::floor(std::log10(a))))) << v;
  return s.str();
}

std::string ratio(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << v;
  return s.str();
}

std::string percent(double v, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << 100.0 * v << " %";
  return s.str();
}

/// One block of the table: a title with the unit, and a cell per material and model.
struct Block {
  std::string title;
  /// The cell of one model; `fem` is the same material's FEM (for ratios).
  std::function<std::string(const ModelResponse& r, const ModelResponse& fem, bool is_fem)> cell;
};

/// "718.1" for the FEM, "514.9 (0.72)" for an MSS: the value and its ratio to the FEM.
std::string with_ratio(double v, double fem, bool is_fem) {
  return is_fem ? number(v) : number(v) + " (" + ratio(v / fem) + ")";
}

/// A mark for a model whose static solution is suspect (footnoted under the table).
std::string flags(const ModelResponse& r) {
  std::string f;
  if (!r.converged) f += " †";
  if (r.inverted_tets > 0) f += " ‡";
  return f;
}

std::vector<Block> blocks() {
  static const char* dof[] = {"lateral shear tx, N/mm",
                              "axial ty, N/mm",
                              "anterior-posterior shear tz, N/mm",
                              "flexion-extension rx, N·mm/deg",
                              "axial torsion ry, N·mm/deg",
                              "lateral bending rz, N·mm/deg"};
  std::vector<Block> out = {
      {"Axial stiffness K6_yy, N/mm (linear, at rest; MSS/FEM in brackets)",
       [](const ModelResponse& r, const ModelResponse& f, bool is_fem) {
         return with_ratio(r.axial_stiffness_n_per_mm(), f.axial_stiffness_n_per_mm(), is_fem);
       }},
      {"Superior-plate axial displacement u_y under 500 N compression, mm (negative: towards the "
       "inferior "
       "endplate; MSS/FEM in brackets)",
       [](const ModelResponse& r, const ModelResponse& f, bool is_fem) {
         return with_ratio(r.plate_axial_displacement_mm, f.plate_axial_displacement_mm, is_fem) +
                flags(r);
       }},
      {"Largest vertex displacement max |u| under 500 N compression, mm",
       [](const ModelResponse& r, const ModelResponse&, bool) {
         return number(r.max_displacement_mm) + flags(r);
       }},
      {"Volume change dV/V0 under 500 N compression, % (FEM: P1 volume of the displaced vertices)",
       [](const ModelResponse& r, const ModelResponse&, bool) {
         std::ostringstream s;
         s << std::setprecision(3) << 100.0 * r.volume_change << " %" << flags(r);
         return s.str();
       }},
      {"Nodal displacement error vs FEM under 500 N compression, % (|u_MSS - u_FEM| / |u_FEM|, all "
       "vertices)",
       [](const ModelResponse& r, const ModelResponse&, bool is_fem) {
         return is_fem ? std::string("—") : percent(r.displacement_error, 1) + flags(r);
       }}};
  for (int i : {0, 2, 3, 4, 5})
    out.push_back(
        {std::string("6x6 diagonal, ") + dof[i] + " (linear, at rest; MSS/FEM in brackets)",
         [i](const ModelResponse& r, const ModelResponse& f, bool is_fem) {
           return with_ratio(r.stiffness_diagonal(i), f.stiffness_diagonal(i), is_fem);
         }});
  return out;
}

nlohmann::json response_json(const ModelResponse& r, bool is_fem) {
  if (!r.available) return nullptr;
  nlohmann::json j = {{"axial_stiffness_n_per_mm", r.axial_stiffness_n_per_mm()},
                      {"stiffness_diagonal", to_json(Eigen::VectorXd(r.stiffness_diagonal))},
                      {"plate_axial_displacement_mm", r.plate_axial_displacement_mm},
                      {"max_displacement_mm", r.max_displacement_mm},
                      {"volume_change", r.volume_change}};
  if (!is_fem) {
    j["displacement_error"] = r.displacement_error;
    j["converged"] = r.converged;
    j["inverted_tets"] = r.inverted_tets;
    j["newton_iterations"] = r.newton_iterations;
    if (!r.message.empty()) j["message"] = r.message;
  }
  return j;
}

}  // namespace

MaterialResult study_material(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                              const MaterialsStudyOptions& options, const StageHooks& hooks) {
  mesh::require_endplate_labels(m);
  MaterialResult r;
  r.material = materials.name;
  const auto& annulus = materials.at(int(mesh::Region::annulus));
  const auto& nucleus = materials.at(int(mesh::Region::nucleus));
  r.e_annulus_mpa = annulus.youngs_modulus_mpa;
  r.e_nucleus_mpa = nucleus.youngs_modulus_mpa;
  r.nu_annulus = annulus.poisson_ratio;
  r.nu_nucleus = nucleus.poisson_ratio;
  const Eigen::Vector3d c = fem::DiscFem::default_plate_center(m);
  const fem::Vector6d wrench = fem::global_wrench(fem::load_case("compression"), m.frame);

  // 1. FEM reference: K6 and the compression, linear.
  hook(hooks.begin, materials.name + ": FEM P" + std::to_string(options.fem_order) + " reference");
  Timer t0;
  const fem::DiscFem fem(m, materials, options.fem_order, c);
  const fem::PlateSolution f = fem.solve_wrench(wrench);
  r.fem.stiffness_diagonal = disc_frame_diagonal(fem.stiffness_6x6(), m.frame);
  r.fem.plate_axial_displacement_mm = axial_translation(f.plate_motion, m.frame);
  r.fem.max_displacement_mm = f.displacement_mm.rowwise().norm().maxCoeff();
  r.fem.volume_change = p1_volume_change(m, f.displacement_mm);
  r.fem_seconds = t0.seconds();
  hook(hooks.end, std::to_string(fem.num_dofs()) + " DOF");

  // 2. Calibration (linear; its own FEM reference on the same mesh and order).
  hook(hooks.begin, materials.name + ": calibrating (" + term_set_name(options.terms) + ", Ipopt)");
  t0.restart();
  CalibrationRequest rq;
  rq.train = fem::parse_load_cases(kTrainCases);
  for (const auto& lc : fem::standard_load_cases())
    if (std::none_of(rq.train.begin(), rq.train.end(),
                     [&](const fem::LoadCase& t) { return t.name == lc.name; }))
      rq.holdout.push_back(lc);
  rq.fem_order = options.fem_order;
  rq.terms = options.terms;
  rq.nonlinear_check = false;
  const CalibrationOutcome o = calibrate_disc(m, materials, rq);
  r.calibrated = o.result.success;
  r.calibration_status = o.result.status;
  r.ipopt_iterations = o.result.iterations;
  r.scales = o.tuned.scales;
  r.calibration_seconds = t0.seconds();
  hook(hooks.end, o.result.status + ", " + std::to_string(o.result.iterations) + " iterations");

  // 3. Untuned thesis network and tuned MSS under the same wrench, nonlinear static.
  t0.restart();
  hook(hooks.begin, materials.name + ": untuned MSS, static under 500 N");
  const mss::MssModel untuned(m, materials, term_set_options(TermSet::thesis));
  r.untuned = mss_response(untuned, wrench, c, o.k6_untuned, f);
  hook(hooks.end, std::to_string(r.untuned.newton_iterations) + " Newton iterations");
  hook(hooks.begin, materials.name + ": tuned MSS, static under 500 N");
  if (o.result.success) {
    const mss::MssModel tuned(m, materials, o.tuned.mss_options());
    r.tuned = mss_response(tuned, wrench, c, o.k6_tuned, f);
    hook(hooks.end, std::to_string(r.tuned.newton_iterations) + " Newton iterations");
  } else {
    r.tuned.available = false;
    hook(hooks.end, "skipped: the calibration failed");
  }
  r.mss_seconds = t0.seconds();
  return r;
}

std::string describe_material(const mesh::RegionMaterials& materials) {
  const auto& a = materials.at(int(mesh::Region::annulus));
  const auto& n = materials.at(int(mesh::Region::nucleus));
  std::ostringstream s;
  s << std::setprecision(4) << "E " << a.youngs_modulus_mpa;
  if (n.youngs_modulus_mpa != a.youngs_modulus_mpa) s << "/" << n.youngs_modulus_mpa;
  s << " MPa, nu " << a.poisson_ratio;
  if (n.poisson_ratio != a.poisson_ratio) s << "/" << n.poisson_ratio;
  if (!materials.by_region.empty()) s << " (annulus/nucleus)";
  const auto f = materials.fibres.find(int(mesh::Region::annulus));
  if (f != materials.fibres.end())
    s << "; annulus fibres E_f " << f->second.modulus_inner_mpa << "-"
      << f->second.modulus_outer_mpa << " MPa at +-" << f->second.angle_inner_deg << "-"
      << f->second.angle_outer_deg << " deg (inner-outer)";
  return s.str();
}

void print_materials(std::ostream& os, const std::vector<MaterialResult>& results, int fem_order,
                     bool markdown) {
  const std::string fem_head = "FEM P" + std::to_string(fem_order);
  const char* heads[] = {"untuned MSS", "tuned MSS"};
  bool any_unconverged = false, any_inverted = false, any_failed = false;
  for (const Block& b : blocks()) {
    if (markdown)
      os << "**" << b.title << "**\n\n| material | " << fem_head << " | " << heads[0] << " | "
         << heads[1] << " |\n|---|---:|---:|---:|\n";
    else
      os << b.title << "\n  " << pad("material", 18, true) << pad(fem_head, 14) << pad(heads[0], 20)
         << pad(heads[1], 20) << "\n";
    for (const MaterialResult& r : results) {
      const std::string cells[] = {
          b.cell(r.fem, r.fem, true), b.cell(r.untuned, r.fem, false),
          r.tuned.available ? b.cell(r.tuned, r.fem, false) : "calibration failed"};
      if (markdown)
        os << "| " << r.material << " | " << cells[0] << " | " << cells[1] << " | " << cells[2]
           << " |\n";
      else
        os << "  " << pad(r.material, 18, true) << pad(cells[0], 14) << pad(cells[1], 20)
           << pad(cells[2], 20) << "\n";
      for (const ModelResponse* m : {&r.untuned, &r.tuned})
        if (m->available) any_unconverged |= !m->converged, any_inverted |= m->inverted_tets > 0;
      any_failed |= !r.tuned.available;
    }
    os << "\n";
  }
  if (any_unconverged)
    os << "† the static MSS solve did not converge (the last iterate is shown).\n";
  if (any_inverted) os << "‡ tetrahedra inside out at the MSS equilibrium.\n";
  if (any_failed)
    os << "calibration failed: Ipopt did not converge for that material (status in the JSON).\n";
}

std::string materials_csv(const std::vector<MaterialResult>& results) {
  std::ostringstream os;
  os << std::setprecision(10)
     << "material,model,E_annulus_MPa,E_nucleus_MPa,nu_annulus,nu_nucleus,axial_stiffness_N_per_mm,"
        "K_tx_N_per_mm,K_ty_N_per_mm,K_tz_N_per_mm,K_rx_Nmm_per_deg,K_ry_Nmm_per_deg,K_rz_Nmm_per_"
        "deg,"
        "plate_uy_500N_mm,max_displacement_500N_mm,volume_change_500N,displacement_error_500N,"
        "converged,"
        "inverted_tets\n";
  for (const MaterialResult& r : results) {
    const std::pair<const char*, const ModelResponse*> models[] = {
        {"fem", &r.fem}, {"untuned", &r.untuned}, {"tuned", &r.tuned}};
    for (const auto& [name, m] : models) {
      os << r.material << "," << name << "," << r.e_annulus_mpa << "," << r.e_nucleus_mpa << ","
         << r.nu_annulus << "," << r.nu_nucleus;
      if (!m->available) {  // a failed calibration: the row is there, its numbers are not
        os << std::string(11, ',') << ",0,\n";
        continue;
      }
      os << "," << m->axial_stiffness_n_per_mm();
      for (int i = 0; i < 6; ++i) os << "," << m->stiffness_diagonal(i);
      os << "," << m->plate_axial_displacement_mm << "," << m->max_displacement_mm << ","
         << m->volume_change << "," << m->displacement_error << "," << (m->converged ? 1 : 0) << ","
         << m->inverted_tets << "\n";
    }
  }
  return os.str();
}

nlohmann::json materials_json(const std::vector<MaterialResult>& results) {
  nlohmann::json out = nlohmann::json::array();
  for (const MaterialResult& r : results)
    out.push_back({{"material", r.material},
                   {"E_mpa", {{"annulus", r.e_annulus_mpa}, {"nucleus", r.e_nucleus_mpa}}},
                   {"nu", {{"annulus", r.nu_annulus}, {"nucleus", r.nu_nucleus}}},
                   {"fem", response_json(r.fem, true)},
                   {"untuned", response_json(r.untuned, false)},
                   {"tuned", response_json(r.tuned, false)},
                   {"calibration",
                    {{"success", r.calibrated},
                     {"status", r.calibration_status},
                     {"iterations", r.ipopt_iterations},
                     {"scales", r.scales}}},
                   {"timings",
                    {{"fem_s", r.fem_seconds},
                     {"calibration_s", r.calibration_seconds},
                     {"mss_static_s", r.mss_seconds}}}});
  return out;
}

std::string MaterialsStudy::failed() const {
  std::string list;
  for (const auto& r : results)
    if (!r.calibrated) list += (list.empty() ? "" : ", ") + r.material;
  return list;
}

MaterialsStudy run_materials_study(const mesh::TetMesh& mesh,
                                   const std::vector<mesh::RegionMaterials>& materials,
                                   const MaterialsStudyOptions& options, const StageHooks& hooks) {
  if (materials.empty()) throw std::invalid_argument("--materials: give at least one material");
  const Timer timer;
  MaterialsStudy study;
  study.options = options;
  for (const auto& mat : materials)
    study.results.push_back(study_material(mesh, mat, options, hooks));
  study.seconds = timer.seconds();
  return study;
}

void print_materials_header(std::ostream& os, const mesh::TetMesh& m, double cell_size_mm,
                            const MaterialsStudyOptions& options,
                            const std::vector<mesh::RegionMaterials>& materials) {
  os << "Material study (thesis fig. 5.9) on " << m.source << ": " << m.num_vertices() << " nodes, "
     << m.num_tets() << " tets, cell size " << cell_size_mm << " mm\n"
     << "  load: compression, F_y = -500 N on the superior plate (disc frame), inferior "
        "endplate fixed\n"
     << "  FEM P" << options.fem_order
     << ", linear | untuned MSS: thesis network, Van Gelder constants"
     << " | tuned MSS: " << term_set_name(options.terms)
     << " scales calibrated to the FEM | MSS: nonlinear static\n";
  for (const auto& mat : materials)
    os << "  " << mat.name << ": " << describe_material(mat) << "\n";
  os << "\n";
}

nlohmann::json materials_study_json(const mesh::TetMesh& m, const MaterialsStudy& study,
                                    const std::string& csv) {
  const fem::Vector6d w = fem::load_case("compression").wrench_local;
  return {
      {"study", "materials"},
      {"thesis", "5.3 test 2, fig. 5.9"},
      {"level", study.level},
      {"cell_size_mm", study.cell_size_mm},
      {"mesh", study_mesh_json(m)},
      {"fem_order", study.options.fem_order},
      {"untuned",
       "thesis network (main + radial + torsion springs), Van Gelder constants, scales 1"},
      {"tuned_terms", term_set_name(study.options.terms)},
      {"load", {{"case", "compression"}, {"wrench_local", to_json(Eigen::VectorXd(w))}}},
      {"units",
       {{"frame", "disc (x lateral, y axial, z anterior)"},
        {"wrench_local", "Fx,Fy,Fz [N], Mx,My,Mz [N·mm]"},
        {"stiffness_diagonal", "tx,ty,tz [N/mm], rx,ry,rz [N·mm/deg], linear at rest"},
        {"plate_axial_displacement_mm",
         "superior plate u_y under the load, mm, negative towards the inferior endplate"},
        {"max_displacement_mm", "largest vertex displacement under the load, mm"},
        {"volume_change",
         "(V - V0)/V0 under the load; FEM: P1 volume of the mesh with displaced vertices"},
        {"displacement_error", "|u_MSS - u_FEM|_F / |u_FEM|_F over the vertices, under the load"}}},
      {"materials", materials_json(study.results)},
      {"csv", csv.empty() ? nlohmann::json(nullptr) : nlohmann::json(csv)},
      {"seconds", study.seconds}};
}

}  // namespace spinesim::studies
