#include "spinesim/studies/disc_validation.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/fem/nonlinear_disc.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

namespace spinesim::studies {
namespace {

/// Mean distance between the endplates along the disc axis, mm.
double disc_height_mm(const mesh::TetMesh& m) {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  int nl = 0, nh = 0;
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    if (m.surface(i) == int(mesh::Surface::inferior_endplate)) lo += m.V.row(i).transpose(), ++nl;
    if (m.surface(i) == int(mesh::Surface::superior_endplate)) hi += m.V.row(i).transpose(), ++nh;
  }
  return (hi / nh - lo / nl).dot(m.frame.axes.col(1));
}

/// The file's targets beside `ours` (quantity → value; NaN or absent: not computed).
void fill_rows(const nlohmann::json& targets, const std::map<std::string, double>& ours,
               DiscValidationResult& r, const std::map<std::string, std::string>& notes = {}) {
  for (const auto& t : targets.at("targets")) {
    DiscValidationRow row = disc_target_row(t);
    const auto it = ours.find(row.quantity);
    if (it == ours.end())
      row.note = "not a quantity this study computes";
    else
      row.ours = it->second;
    if (const auto n = notes.find(row.quantity); n != notes.end() && !std::isfinite(row.ours))
      row.note = n->second;
    r.rows.push_back(row);
  }
}

/// The study's frame-independent facts of the disc.
DiscValidationResult describe(const mesh::TetMesh& m, const mesh::RegionMaterials& materials,
                              const nlohmann::json& targets, const std::string& mesh_label) {
  DiscValidationResult r;
  r.material = materials.name;
  r.mesh_label = mesh_label;
  r.tets = m.num_tets();
  r.source = targets.value("source", std::string());
  r.whole_segments = targets.value("whole_segments", nlohmann::json::array());
  r.disc_height_mm = disc_height_mm(m);
  r.disc_area_mm2 = mesh::mesh_volume(m) / r.disc_height_mm;
  return r;
}

}  // namespace

std::string disc_target_preparation(const nlohmann::json& t) {
  const auto flag = [&](const char* key) -> int {
    if (!t.contains(key) || t.at(key).is_null()) return -1;
    return t.at(key).get<bool>() ? 1 : 0;
  };
  const int facets = flag("facets_removed"), ligaments = flag("ligaments_removed");
  if (facets < 0 || ligaments < 0) return "not stated in what we read";
  if (facets && ligaments) return "facets and ligaments removed";
  if (facets) return "facets removed, ligaments kept";
  return "posterior elements present";
}

DiscValidationRow disc_target_row(const nlohmann::json& t) {
  DiscValidationRow row;
  row.quantity = t.at("quantity").get<std::string>();
  row.units = t.value("units", std::string());
  row.low = t.at("low").get<double>();
  row.high = t.at("high").get<double>();
  row.reported = t.value("reported", std::string());
  row.source = t.value("source", std::string());
  row.preparation = disc_target_preparation(t);
  return row;
}

nlohmann::json disc_target_json(const DiscValidationRow& row) {
  return {{"quantity", row.quantity}, {"units", row.units},       {"low", row.low},
          {"high", row.high},         {"reported", row.reported}, {"source", row.source}};
}

const std::vector<std::pair<const char*, int>>& nonlinear_disc_cases() {
  static const std::vector<std::pair<const char*, int>> cases = {
      {"compression", 1}, {"torsion", 4}, {"flexion", 3}, {"extension", 3}, {"lateral-bending", 5}};
  return cases;
}

nlohmann::json read_disc_targets(const std::string& path) {
  const nlohmann::json j = read_json_file(path, "disc targets file");
  if (!j.is_object() || !j.contains("targets") || !j.at("targets").is_array())
    throw std::invalid_argument("disc targets file '" + path + "': expected a 'targets' array");
  for (const auto& t : j.at("targets")) {
    if (!t.is_object() || !t.contains("quantity") || !t.at("quantity").is_string() ||
        !t.contains("low") || !t.at("low").is_number() || !t.contains("high") ||
        !t.at("high").is_number())
      throw std::invalid_argument("disc targets file '" + path +
                                  "': every target needs 'quantity', 'low' and 'high'");
    for (const char* key : {"units", "reported", "source"})
      if (t.contains(key) && !t.at(key).is_string())
        throw std::invalid_argument("disc targets file '" + path + "': '" + key +
                                    "' must be a string");
    for (const char* key : {"facets_removed", "ligaments_removed"})
      if (t.contains(key) && !t.at(key).is_boolean() && !t.at(key).is_null())
        throw std::invalid_argument("disc targets file '" + path + "': '" + key +
                                    "' must be true, false or null");
  }
  if (j.contains("source") && !j.at("source").is_string())
    throw std::invalid_argument("disc targets file '" + path + "': 'source' must be a string");
  if (j.contains("whole_segments") && !j.at("whole_segments").is_array())
    throw std::invalid_argument("disc targets file '" + path +
                                "': 'whole_segments' must be an array");
  return j;
}

DiscValidationResult run_disc_validation(const mesh::TetMesh& m,
                                         const mesh::RegionMaterials& materials,
                                         fem::Formulation formulation,
                                         const nlohmann::json& targets,
                                         const std::string& mesh_label, const StageHooks& hooks) {
  DiscValidationResult r = describe(m, materials, targets, mesh_label);
  r.formulation = formulation_name(formulation);

  hooks.begin_stage(std::string("FEM ") + r.formulation + ", " + materials.name);
  const Timer timer;
  fem::SolverOptions options;
  options.formulation = formulation;
  const fem::DiscFem solver(m, materials, 2, fem::DiscFem::default_plate_center(m), options);
  r.dofs = solver.num_dofs();
  // Stiffness of one case: its load over the plate motion along the load, disc frame. The
  // compression's solution also gives the nucleus pressure.
  const Eigen::Matrix3d& axes = m.frame.axes;
  fem::PlateSolution compression;
  const auto stiffness = [&](const char* name, int component) {
    const fem::LoadCase& c = fem::load_case(name);
    const fem::PlateSolution s = solver.solve_wrench(fem::global_wrench(c, m.frame));
    if (component == 1) compression = s;
    const Eigen::Vector3d t = axes.transpose() * s.plate_motion.head<3>();
    const Eigen::Vector3d theta = axes.transpose() * s.plate_motion.tail<3>();
    if (component < 3) return std::abs(c.wrench_local(component) / t(component)) / 1000.0;
    return std::abs(c.wrench_local(component) / 1000.0 / (theta(component - 3) * kDegPerRad));
  };
  std::map<std::string, double> ours = {{"compression", stiffness("compression", 1)},
                                        {"torsion", stiffness("torsion", 4)},
                                        {"flexion", stiffness("flexion", 3)},
                                        {"extension", stiffness("extension", 3)},
                                        {"lateral-bending", stiffness("lateral-bending", 5)}};
  r.nucleus_pressure_mpa = compression.nucleus_pressure_mpa;
  const double mean_stress =
      std::abs(fem::load_case("compression").wrench_local(1)) / r.disc_area_mm2;
  ours["nucleus-pressure-ratio"] = r.nucleus_pressure_mpa / mean_stress;
  r.solve_s = timer.seconds();
  hooks.end_stage(std::to_string(r.dofs) + " DOF");

  fill_rows(targets, ours, r, {{"nucleus-pressure-ratio", "needs --formulation mixed"}});
  return r;
}

NonlinearDiscQuantities nonlinear_disc_quantities(const mesh::TetMesh& m,
                                                  const mesh::RegionMaterials& materials,
                                                  const NonlinearDiscOptions& options,
                                                  const StageHooks& hooks) {
  if (options.order != 1 && options.order != 2)
    throw std::invalid_argument("nonlinear disc: order must be 1 or 2");
  const double k2 = options.fibre_k2.value_or(fem::material_fibre_k2(materials));
  if (!std::isfinite(k2) || k2 < 0)
    throw std::invalid_argument("nonlinear disc: the fibre toe exponent k2 must be >= 0");
  if (options.load_increments < 1 || options.load_increments > 1000)
    throw std::invalid_argument("nonlinear disc: load increments must be 1 to 1000");
  if (!std::isfinite(options.preload_n) || options.preload_n < 0 || options.preload_n > 1e4)
    throw std::invalid_argument("nonlinear disc: the preload must be 0 to 10000 N");
  NonlinearDiscQuantities out;
  out.fibre_k2 = k2;
  const double area_mm2 = mesh::mesh_volume(m) / disc_height_mm(m);
  const fem::NonlinearDisc disc(m, fem::disc_element_materials(m, materials, k2), options.order,
                                fem::DiscFem::default_plate_center(m));
  out.dofs = 3 * disc.body().space().num_nodes();
  fem::NewtonOptions newton;
  newton.load_increments = options.load_increments;
  const Eigen::Matrix3d& axes = m.frame.axes;
  // The preload alone: the state the moment cases' rotations are measured from.
  const fem::LoadCase& compression = fem::load_case("compression");
  fem::PlateLoad preload;
  preload.value = fem::global_wrench(compression, m.frame) *
                  (options.preload_n / std::abs(compression.wrench_local(1)));
  Eigen::Matrix<double, 6, 1> preloaded = Eigen::Matrix<double, 6, 1>::Zero();
  if (options.preload_n > 0) {
    hooks.begin_stage("nonlinear disc, preload " + significant(options.preload_n, 4) + " N");
    const fem::NonlinearPlateSolution s = disc.solve(preload, newton);
    if (!s.body.converged)
      throw std::runtime_error("nonlinear disc: the preload did not converge: " + s.body.failure);
    preloaded = s.plate_motion;
    hooks.end_stage(std::to_string(s.body.newton_iterations) + " Newton iterations");
  }
  for (const auto& [name, component] : nonlinear_disc_cases()) {
    hooks.begin_stage(std::string("nonlinear disc, ") + name);
    const fem::LoadCase& c = fem::load_case(name);
    const bool moment = component >= 3;
    fem::PlateLoad load;
    load.value = fem::global_wrench(c, m.frame) + (moment ? preload.value : 0 * preload.value);
    fem::NonlinearPlateSolution s = disc.solve(load, newton);
    if (moment) {
      s.plate_motion -= preloaded;
      for (fem::PlatePathPoint& p : s.path) p.plate_motion -= p.load_fraction * preloaded;
    }
    // Motion along the case's component, disc frame: mm, or degrees.
    const auto along = [&](const Eigen::Matrix<double, 6, 1>& q) {
      return component < 3 ? (axes.transpose() * q.head<3>())(component)
                           : (axes.transpose() * q.tail<3>())(component - 3) * kDegPerRad;
    };
    const double load_value =
        component < 3 ? c.wrench_local(component) : c.wrench_local(component) / 1000.0;
    DiscLoadPath path{name, component < 3 ? "N" : "N m", component < 3 ? "mm" : "deg", {}, {}};
    for (const fem::PlatePathPoint& p : s.path) {
      path.load.push_back(std::abs(p.load_fraction * load_value));
      path.motion.push_back(std::abs(along(p.plate_motion)));
    }
    out.paths.push_back(path);
    out.newton_iterations += s.body.newton_iterations;
    if (!s.body.converged) {
      out.notes[name] = "did not converge: " + s.body.failure;
      hooks.end_stage("did not converge");
      continue;
    }
    out.values[name] =
        std::abs(load_value / along(s.plate_motion)) / (component < 3 ? 1000.0 : 1.0);
    if (component == 1) {
      out.nucleus_pressure_mpa = s.nucleus_pressure_mpa;
      out.values["nucleus-pressure-ratio"] =
          s.nucleus_pressure_mpa / (std::abs(c.wrench_local(1)) / area_mm2);
    }
    hooks.end_stage(std::to_string(s.body.newton_iterations) + " Newton iterations");
  }
  if (!out.values.count("compression"))
    out.notes["nucleus-pressure-ratio"] = "the compression did not converge";
  return out;
}

DiscValidationResult run_nonlinear_disc_validation(const mesh::TetMesh& m,
                                                   const mesh::RegionMaterials& materials,
                                                   const NonlinearDiscOptions& options,
                                                   const nlohmann::json& targets,
                                                   const std::string& mesh_label,
                                                   const StageHooks& hooks) {
  DiscValidationResult r = describe(m, materials, targets, mesh_label);
  const Timer timer;
  const NonlinearDiscQuantities q = nonlinear_disc_quantities(m, materials, options, hooks);
  r.formulation = std::string("nonlinear P") + std::to_string(options.order) +
                  (options.order == 1 ? ", nodal-average volume" : ", mean dilatation") +
                  "; tension-only fibres, k1 = k/4, k2 = " + significant(q.fibre_k2, 3);
  r.dofs = q.dofs;
  r.paths = q.paths;
  r.nucleus_pressure_mpa = q.nucleus_pressure_mpa;
  r.solve_s = timer.seconds();
  fill_rows(targets, q.values, r, q.notes);
  return r;
}

void write_disc_paths_csv(std::ostream& os, const DiscValidationResult& r) {
  os << "load_case,load,load_units,motion,motion_units\n";
  for (const DiscLoadPath& p : r.paths)
    for (std::size_t k = 0; k < p.load.size(); ++k)
      os << p.load_case << "," << significant(p.load[k], 6) << "," << p.load_units << ","
         << significant(p.motion[k], 6) << "," << p.motion_units << "\n";
}

void print_disc_validation(std::ostream& os, const DiscValidationResult& r, bool markdown) {
  os << "Disc validation: " << r.mesh_label << " (" << r.tets << " tets, " << r.dofs
     << " DOF), material " << r.material << ", " << r.formulation
     << (r.paths.empty() ? " formulation" : "") << "\n"
     << "  disc height " << significant(r.disc_height_mm, 3) << " mm, mean cross-section "
     << significant(r.disc_area_mm2, 4) << " mm^2; nucleus pressure at 500 N "
     << significant(r.nucleus_pressure_mpa, 3) << " MPa\n"
     << "  stiffness = load / plate motion at 500 N and 7.5 N·m (disc frame, about the plate "
        "centre)\n\n";
  TextTable table({"quantity", "units", "ours", "in vitro", "window", "verdict", "tested as"}, 2);
  int matches = 0, compared = 0;
  for (const DiscValidationRow& row : r.rows) {
    const bool have = std::isfinite(row.ours);
    compared += have;
    matches += have && row.match();
    table.add({row.quantity, row.units, significant(row.ours, 3), row.reported,
               significant(row.low, 3) + " - " + significant(row.high, 3),
               have ? (row.match() ? "MATCH" : "MISS") : "n/a (" + row.note + ")",
               row.preparation});
  }
  table.print(os, markdown);
  os << "\n  " << matches << " of " << compared << " inside the in-vitro window.\n";
  if (r.whole_segments.is_array() && !r.whole_segments.empty()) {
    os << "  Whole motion segments (posterior elements present; for scale, not targets):";
    for (const auto& w : r.whole_segments) {
      const auto text = [&w](const char* key) {
        return w.is_object() && w.contains(key) && w.at(key).is_string()
                   ? w.at(key).get<std::string>()
                   : std::string();
      };
      os << " " << text("quantity") << " " << text("reported") << " " << text("units") << ";";
    }
    os << "\n";
  }
  os << "  Sources: data/validation/disc_in_vitro.json (each row's 'source').\n";
}

nlohmann::json disc_validation_json(const DiscValidationResult& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const DiscValidationRow& row : r.rows) {
    nlohmann::json j = disc_target_json(row);
    j["tested_as"] = row.preparation;
    if (std::isfinite(row.ours)) {
      j["ours"] = row.ours;
      j["verdict"] = row.match() ? "MATCH" : "MISS";
    } else {
      j["ours"] = nullptr;
      j["verdict"] = "n/a";
      j["note"] = row.note;
    }
    rows.push_back(j);
  }
  nlohmann::json j = {{"mesh", r.mesh_label},
                      {"tets", r.tets},
                      {"dofs", r.dofs},
                      {"material", r.material},
                      {"formulation", r.formulation},
                      {"disc_height_mm", r.disc_height_mm},
                      {"disc_area_mm2", r.disc_area_mm2},
                      {"rows", rows},
                      {"whole_segments", r.whole_segments},
                      {"solve_s", r.solve_s}};
  if (!r.paths.empty()) {
    nlohmann::json paths = nlohmann::json::array();
    for (const DiscLoadPath& p : r.paths)
      paths.push_back({{"load_case", p.load_case},
                       {"load_units", p.load_units},
                       {"motion_units", p.motion_units},
                       {"load", p.load},
                       {"motion", p.motion}});
    j["paths"] = paths;
  }
  j["nucleus_pressure_mpa"] = std::isfinite(r.nucleus_pressure_mpa)
                                  ? nlohmann::json(r.nucleus_pressure_mpa)
                                  : nlohmann::json(nullptr);
  return j;
}

void write_disc_validation_csv(std::ostream& os, const DiscValidationResult& r) {
  os << "quantity,units,ours,low,high,verdict\n";
  for (const DiscValidationRow& row : r.rows)
    os << row.quantity << "," << row.units << ","
       << (std::isfinite(row.ours) ? significant(row.ours, 6) : "") << "," << row.low << ","
       << row.high << "," << (std::isfinite(row.ours) ? (row.match() ? "MATCH" : "MISS") : "n/a")
       << "\n";
}

}  // namespace spinesim::studies
