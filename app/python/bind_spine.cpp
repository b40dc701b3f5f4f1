// spinesim.spine (standing equilibrium under loads) and spinesim.seated_spine (a chair).
#include "bindings.hpp"

#include "spinesim/spine/model.hpp"
#include "spinesim/studies/seating_study.hpp"
#include "spinesim/studies/spine_solve.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

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
};

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
  return o;
}

py::object solve_spine(const VectorsByVertebra& forces, const VectorsByVertebra& moments,
                       const std::string& fusion, bool muscles, bool trunk_muscles, bool gravity,
                       const std::string& disc_joints, const std::string& ligaments,
                       double height_m, double body_mass_kg, const std::string& sex,
                       bool rib_cage) {
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
                           {height_m, body_mass_kg, sex, rib_cage});
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
                  double body_mass_kg, const std::string& sex, bool rib_cage) {
  studies::SeatingRequest rq;
  for (const auto& [name, value] : chair) rq = studies::with_parameter(rq, name, value);
  rq.chair.armrests = armrests;
  if (!chair_surface.empty()) {
    rq.chair.surface = studies::read_chair_surface(chair_surface);
    rq.chair.surface_name = chair_surface;
  }
  rq.model = model_options(fusion, true, true, true, disc_joints, ligaments,
                           {height_m, body_mass_kg, sex, rib_cage});
  studies::check_seating_request(rq);
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = studies::seating_json(studies::run_seating(data_folder(), rq));
  }
  return to_python(j);
}

}  // namespace

void bind_spine(py::module_& m) {
  m.def("_spine", &solve_spine);
  m.def("_seated_spine", &seated);
  m.def("seating_parameters", &studies::seating_parameters,
        "The chair parameters seated_spine takes (as keyword arguments, deg or mm)");
}

}  // namespace spinesim::python
