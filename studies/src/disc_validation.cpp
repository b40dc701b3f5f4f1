#include "spinesim/studies/disc_validation.hpp"
#include "spinesim/common/constants.hpp"

#include "spinesim/common/input_file.hpp"
#include "spinesim/common/timer.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/toolkit.hpp"

#include <cmath>
#include <map>
#include <stdexcept>

namespace spinesim::studies {
namespace {

std::string preparation_of(const nlohmann::json& t) {
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

}  // namespace

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
  DiscValidationResult r;
  r.material = materials.name;
  r.formulation = formulation_name(formulation);
  r.mesh_label = mesh_label;
  r.tets = m.num_tets();
  r.source = targets.value("source", std::string());
  r.whole_segments = targets.value("whole_segments", nlohmann::json::array());
  r.disc_height_mm = disc_height_mm(m);
  r.disc_area_mm2 = mesh::mesh_volume(m) / r.disc_height_mm;

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

  for (const auto& t : targets.at("targets")) {
    DiscValidationRow row;
    row.quantity = t.at("quantity").get<std::string>();
    row.units = t.value("units", std::string());
    row.low = t.at("low").get<double>();
    row.high = t.at("high").get<double>();
    row.reported = t.value("reported", std::string());
    row.source = t.value("source", std::string());
    row.preparation = preparation_of(t);
    const auto it = ours.find(row.quantity);
    if (it == ours.end())
      row.note = "not a quantity this study computes";
    else
      row.ours = it->second;
    if (row.quantity == "nucleus-pressure-ratio" && !std::isfinite(row.ours))
      row.note = "needs --formulation mixed";
    r.rows.push_back(row);
  }
  return r;
}

void print_disc_validation(std::ostream& os, const DiscValidationResult& r, bool markdown) {
  os << "Disc validation: " << r.mesh_label << " (" << r.tets << " tets, " << r.dofs
     << " DOF), material " << r.material << ", " << r.formulation << " formulation\n"
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
    nlohmann::json j = {{"quantity", row.quantity},
                        {"units", row.units},
                        {"low", row.low},
                        {"high", row.high},
                        {"reported", row.reported},
                        {"source", row.source},
                        {"tested_as", row.preparation}};
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
