// spinesim.spine (standing equilibrium under loads) and spinesim.seated_spine (a chair).
#include "bindings.hpp"

#include "spinesim/spine/model.hpp"
#include "spinesim/spine/scoliosis.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <array>
#include <map>

namespace spinesim::python {
namespace {

using VectorsByVertebra = std::map<std::string, Eigen::Vector3d>;

/// The body: height (m), mass (kg), sex (zeros are the reference body's) and whether its rib
/// cage is modelled.
struct Body {
  double height_m = 0, body_mass_kg = 0;
  std::string sex = "male";
  bool rib_cage = false;
  spine::ScoliosisCurve scoliosis;  ///< cobb_deg 0: straight
};

/// A curve from Python's scoliosis dict (empty: straight): type and cobb_deg, optionally apex,
/// curve_ends (upper, lower), apical_rotation_deg and convex ("right" or "left").
spine::ScoliosisCurve curve_of(const py::dict& d) {
  if (d.empty()) return {};
  for (const auto& [key, value] : d) {
    const std::string k = py::str(key);
    if (k != "type" && k != "cobb_deg" && k != "apex" && k != "curve_ends" &&
        k != "apical_rotation_deg" && k != "convex")
      throw std::invalid_argument("scoliosis: unknown key '" + k +
                                  "' (type, cobb_deg, apex, curve_ends, apical_rotation_deg, "
                                  "convex)");
  }
  if (!d.contains("type") || !d.contains("cobb_deg"))
    throw std::invalid_argument("scoliosis: give at least type and cobb_deg");
  spine::ScoliosisCurve c =
      spine::scoliosis_curve(d["type"].cast<std::string>(), d["cobb_deg"].cast<double>());
  if (d.contains("apex")) c.apex = d["apex"].cast<std::string>();
  if (d.contains("curve_ends")) {
    const auto ends = d["curve_ends"].cast<std::pair<std::string, std::string>>();
    c.upper_end = ends.first;
    c.lower_end = ends.second;
  }
  if (d.contains("apical_rotation_deg"))
    c.apical_rotation_deg = d["apical_rotation_deg"].cast<double>();
  if (d.contains("convex")) {
    const std::string side = d["convex"].cast<std::string>();
    if (side != "right" && side != "left")
      throw std::invalid_argument("scoliosis: convex must be 'right' or 'left'");
    c.convex_right = side == "right";
  }
  if (d.contains("apex") || d.contains("curve_ends") || d.contains("convex"))
    c.type = "custom (" + c.type + ")";
  spine::check_scoliosis_curve(c);
  return c;
}

spine::ModelOptions model_options(const std::string& fusion, bool muscles, bool trunk_muscles,
                                  bool gravity, const std::string& disc_joints,
                                  const std::string& ligaments, const Body& body) {
  spine::ModelOptions o;
  o.ligaments = spine::parse_ligaments(ligaments);
  o.subject.height_m = body.height_m;
  o.subject.body_mass_kg = body.body_mass_kg;
  o.subject.sex = spine::parse_sex(body.sex);
  o.subject = spine::resolve_subject(data_folder(), o.subject);
  if (!fusion.empty()) o.fused_joints = spine::parse_fusion(fusion);
  o.muscles = muscles;
  o.trunk_muscles = trunk_muscles;
  o.gravity = gravity;
  o.disc_joints = disc_joints;
  o.rib_cage = body.rib_cage;
  o.scoliosis = body.scoliosis;
  return o;
}

py::object solve_spine(const VectorsByVertebra& forces, const VectorsByVertebra& moments,
                       const std::string& fusion, bool muscles, bool trunk_muscles, bool gravity,
                       const std::string& disc_joints, const std::string& ligaments,
                       double height_m, double body_mass_kg, const std::string& sex, bool rib_cage,
                       const py::dict& scoliosis, const std::array<double, 4>& inputs) {
  studies::SpineSolveRequest rq;
  for (const auto& [name, f] : forces) {
    spine::ExternalLoad l;
    l.vertebra = spine::vertebra_index(name);
    l.force_n = f;
    rq.loads.push_back(l);
  }
  for (const auto& [name, mo] : moments) {
    spine::ExternalLoad l;
    l.vertebra = spine::vertebra_index(name);
    l.moment_nmm = mo;
    rq.loads.push_back(l);
  }
  rq.model = model_options(fusion, muscles, trunk_muscles, gravity, disc_joints, ligaments,
                           {height_m, body_mass_kg, sex, rib_cage, curve_of(scoliosis)});
  // muscle_strength, joint_stiffness, ligament_stiffness, inclination_deg (checked by the model)
  rq.model.muscle_strength = inputs[0];
  rq.model.joint_stiffness = inputs[1];
  rq.model.ligament_stiffness = inputs[2];
  rq.model.inclination_deg = inputs[3];
  rq.solve.recruit = muscles;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = studies::spine_solve_json(studies::run_spine_solve(data_folder(), rq), "");
  }
  return to_python(j);
}

py::object seated(const std::map<std::string, double>& chair, bool armrests,
                  const std::string& chair_surface, const std::string& fusion,
                  const std::string& disc_joints, const std::string& ligaments, double height_m,
                  double body_mass_kg, const std::string& sex, bool rib_cage,
                  const py::dict& scoliosis) {
  studies::SeatingRequest rq;
  for (const auto& [name, value] : chair) rq = studies::with_parameter(rq, name, value);
  rq.chair.armrests = armrests;
  if (!chair_surface.empty()) {
    rq.chair.surface = studies::read_chair_surface(chair_surface);
    rq.chair.surface_name = chair_surface;
  }
  rq.model = model_options(fusion, true, true, true, disc_joints, ligaments,
                           {height_m, body_mass_kg, sex, rib_cage, curve_of(scoliosis)});
  studies::check_seating_request(rq);
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = studies::seating_json(studies::run_seating(data_folder(), rq));
  }
  return to_python(j);
}

/// A named body as a dict (name, height_m, body_mass_kg, sex, source).
py::dict body_dict(const spine::NamedBody& b) {
  py::dict d;
  d["name"] = b.name;
  d["height_m"] = b.subject.height_m;
  d["body_mass_kg"] = b.subject.body_mass_kg;
  d["sex"] = spine::sex_name(b.subject.sex);
  d["source"] = b.source;
  return d;
}

}  // namespace

void bind_spine(py::module_& m) {
  m.def("named_bodies", [] {
    py::list out;
    for (const spine::NamedBody& b : spine::named_bodies(data_folder())) out.append(body_dict(b));
    return out;
  }, "The sourced bodies (spine_model.json anthropometry.bodies), smallest first: name, "
     "height_m, body_mass_kg, sex, source");
  m.def("_named_body",
        [](const std::string& name) { return body_dict(spine::named_body(data_folder(), name)); });
  m.def("_spine", &solve_spine);
  m.def("_seated_spine", &seated);
  m.def("seating_parameters", &studies::seating_parameters,
        "The chair parameters seated_spine takes (as keyword arguments, deg or mm)");
}

}  // namespace spinesim::python
