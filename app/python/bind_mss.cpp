// spinesim.MassSpringDisc (the model, its static solve), spinesim.Simulation (stepping it in
// time under a moving or loaded plate) and spinesim.calibrate.
#include "bindings.hpp"
#include "flag_values.hpp"

#include "spinesim/calibration/protocol.hpp"
#include "spinesim/calibration/tuned_disc.hpp"
#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mss/quantities.hpp"
#include "spinesim/mss/solver.hpp"
#include "spinesim/output/files.hpp"
#include "spinesim/studies/comparison_report.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/mss_run.hpp"
#include "spinesim/studies/mss_verbs.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

namespace spinesim::python {
namespace {

using RowPositions = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

/// 3#nodes interleaved positions as an (N, 3) array.
Eigen::MatrixX3d as_rows(const Eigen::VectorXd& x) {
  return Eigen::Map<const RowPositions>(x.data(), x.size() / 3, 3);
}

/// The cell arrays of a state, by name (volume_change, green_lagrange_strain, edge_spring_force_N).
py::dict fields_of(const mss::MssModel& model, const Eigen::VectorXd& x) {
  py::dict d;
  for (const auto& a : mss::state_fields(model, x).cell)
    d[py::str(a.name)] = a.values.cols() == 1 ? py::cast(Eigen::VectorXd(a.values.col(0)))
                                              : py::cast(a.values);
  return d;
}

/// The plate load from exactly one of a named case, a motion (mm, deg) and a wrench (none: zero
/// motion), about `center` (default: the mesh's plate centre).
studies::PlateLoad plate_load(const mesh::TetMesh& m, const std::string& load_case,
                              const std::optional<mss::Vector6d>& motion_deg,
                              const std::optional<mss::Vector6d>& wrench,
                              const std::optional<Eigen::Vector3d>& center) {
  if (int(!load_case.empty()) + int(motion_deg.has_value()) + int(wrench.has_value()) > 1)
    throw std::invalid_argument("give at most one of case, motion_deg and wrench");
  studies::PlateLoad load;
  load.center = center ? *center : mss::default_plate_center(m);
  if (!load_case.empty()) {
    load.is_wrench = true;
    load.value = fem::global_wrench(fem::load_case(load_case), m.frame);
  } else if (wrench) {
    load.is_wrench = true;
    load.value = *wrench;
  } else if (motion_deg) {
    load.value = studies::motion_deg_to_rad(*motion_deg);
  }
  return load;
}

/// An MSS disc: the mesh, its material or tuned constants, and the model built from them.
struct MassSpringDisc {
  std::shared_ptr<const mss::MssModel> model;
  studies::MssModelChoice choice;
};

MassSpringDisc make_disc(const mesh::TetMesh& m, const std::string& material,
                         const std::string& params, bool volume_term, bool fibre_springs,
                         double damping_n_s_per_mm) {
  studies::MssModelRequest rq;
  rq.material = material;
  rq.material_given = !params.empty() && material != "real-disc";
  rq.params = params;
  rq.options.volume_term = volume_term;
  rq.options.fibre_springs = fibre_springs;
  rq.options.damping_n_s_per_mm = damping_n_s_per_mm;
  MassSpringDisc d;
  d.choice = studies::choose_mss_model(rq, data_folder());
  py::gil_scoped_release release;
  d.model = std::make_shared<const mss::MssModel>(studies::build_mss_model(m, d.choice, true));
  return d;
}

py::dict solve_static(const MassSpringDisc& d, const studies::PlateLoad& load) {
  studies::MssRunRequest rq;
  rq.load = load;
  studies::MssRunResult r;
  {
    py::gil_scoped_release release;
    r = studies::run_mss_load(*d.model, rq);
  }
  if (r.failed) throw std::runtime_error("the MSS did not reach equilibrium: " + r.failure);
  py::dict out;
  out["positions_mm"] = as_rows(r.x_mm);
  out["displacement_mm"] = as_rows(r.x_mm - d.model->rest_positions_mm());
  out["plate_motion_deg"] = mss::Vector6d(studies::motion_rad_to_deg(r.plate_motion));
  out["reaction_wrench"] = r.reaction_wrench;
  out["fields"] = fields_of(*d.model, r.x_mm);
  out["summary"] = to_python(studies::mss_run_json(r));
  return out;
}

/// A time-stepped MSS disc under a plate that the caller moves or loads step by step.
class Simulation {
 public:
  Simulation(std::shared_ptr<const mss::MssModel> model, const mss::DynamicsOptions& options)
      : model_(std::move(model)), sim_(*model_, options), state_(sim_.rest_state()),
        center_(mss::default_plate_center(model_->mesh())) {}

  /// `steps` steps towards the plate load; false (state kept, message set) on a rejected step.
  void step(const studies::PlateLoad& load, int steps) {
    if (steps < 1) throw std::invalid_argument("steps must be >= 1");
    py::gil_scoped_release release;
    const mss::Boundary bc = load.boundary(1.0);
    for (int i = 0; i < steps; ++i) {
      const mss::StepReport rep = sim_.step(state_, bc);
      if (!rep.ok) throw std::runtime_error("step rejected at t = " +
                                            std::to_string(state_.time_s) + " s: " + rep.message);
    }
    center_ = load.center;
  }
  Eigen::MatrixX3d positions() const { return as_rows(state_.x_mm); }
  Eigen::MatrixX3d velocities() const { return as_rows(state_.v_mm_s); }
  Eigen::MatrixX3d displacement() const {
    return as_rows(state_.x_mm - model_->rest_positions_mm());
  }
  double time_s() const { return state_.time_s; }
  mss::Vector6d plate_q() const { return state_.plate_q; }
  /// The wrench the disc exerts on the plate, about the plate's moved centre.
  mss::Vector6d reaction() const {
    const Eigen::Vector3d c = center_ + state_.plate_q.head<3>();
    return mss::plate_reaction(*model_, state_.x_mm, c);
  }
  py::dict fields() const { return fields_of(*model_, state_.x_mm); }
  void reset() { state_ = sim_.rest_state(); }
  const mss::MssModel& model() const { return *model_; }

 private:
  std::shared_ptr<const mss::MssModel> model_;
  mss::Simulator sim_;
  mss::State state_;
  Eigen::Vector3d center_;
};

void bind_disc(py::module_& m) {
  py::class_<MassSpringDisc>(m, "MassSpringDisc", R"(The mass-spring disc of a mesh.

material  a preset (real-disc, thesis-disc, fibre-reinforced, ...) or a material JSON file
params    a tuned file from spinesim.calibrate or `spinesim calibrate` (its terms and scales), or "")")
      .def(py::init(&make_disc), py::arg("mesh"), py::kw_only(), py::arg("material") = "real-disc",
           py::arg("params") = "", py::arg("volume_term") = false, py::arg("fibre_springs") = false,
           py::arg("damping_n_s_per_mm") = -1.0)
      .def_property_readonly("num_nodes", [](const MassSpringDisc& d) { return d.model->num_nodes(); })
      .def_property_readonly("num_springs",
                             [](const MassSpringDisc& d) { return d.model->num_edge_springs(); })
      .def_property_readonly("rest_positions_mm",
                             [](const MassSpringDisc& d) { return as_rows(d.model->rest_positions_mm()); })
      .def_property_readonly("masses_t", [](const MassSpringDisc& d) { return d.model->node_masses_t(); })
      .def_property_readonly("constants", [](const MassSpringDisc& d) { return d.choice.constants; })
      .def_property_readonly("summary", [](const MassSpringDisc& d) {
        return to_python(studies::mss_model_json(*d.model, d.choice.materials));
      })
      .def(
          "_solve",
          [](const MassSpringDisc& d, const std::string& c, const std::optional<mss::Vector6d>& motion,
             const std::optional<mss::Vector6d>& wrench, const std::optional<Eigen::Vector3d>& center) {
            return solve_static(d, plate_load(d.model->mesh(), c, motion, wrench, center));
          })
      .def(
          "simulation",
          [](const MassSpringDisc& d, double dt_s, const std::string& integrator,
             int newton_iterations) {
            mss::DynamicsOptions o;
            o.dt_s = dt_s;
            o.integrator = cli::parse_integrator(integrator);
            o.newton_iterations = newton_iterations;
            return Simulation(d.model, o);
          },
          py::kw_only(), py::arg("dt_s") = 1e-3, py::arg("integrator") = "implicit",
          py::arg("newton_iterations") = 1,
          "A time-stepped run of this disc, starting at rest (integrator: implicit, symplectic or "
          "explicit)");

  py::class_<Simulation>(m, "Simulation", "A time-stepped MSS disc (MassSpringDisc.simulation)")
      .def(
          "_step",
          [](Simulation& s, const std::string& c, const std::optional<mss::Vector6d>& motion,
             const std::optional<mss::Vector6d>& wrench, const std::optional<Eigen::Vector3d>& center,
             int steps) { s.step(plate_load(s.model().mesh(), c, motion, wrench, center), steps); })
      .def_property_readonly("positions_mm", &Simulation::positions)
      .def_property_readonly("velocities_mm_s", &Simulation::velocities)
      .def_property_readonly("displacement_mm", &Simulation::displacement)
      .def_property_readonly("time_s", &Simulation::time_s)
      .def_property_readonly("plate_q", &Simulation::plate_q,
                             "The plate's DOF under a wrench (t mm, theta rad)")
      .def("reaction_wrench", &Simulation::reaction,
           "The wrench (N, N·mm) the disc exerts on the plate, about its moved centre")
      .def("fields", &Simulation::fields, "Per-tet strain and spring forces of the present state")
      .def("reset", &Simulation::reset, "Back to rest, time 0");
}

py::dict calibrate(const mesh::TetMesh& mesh, const std::string& material,
                   const std::vector<std::string>& train, const std::vector<std::string>& holdout,
                   const std::string& terms, int order, bool check, const std::string& out) {
  calibration::CalibrationRequest rq;
  for (const auto& c : train) rq.train.push_back(fem::load_case(c));
  for (const auto& c : holdout) rq.holdout.push_back(fem::load_case(c));
  calibration::check_cases(rq.train, rq.holdout);
  rq.fem_order = order;
  rq.terms = calibration::parse_term_set(terms);
  rq.nonlinear_check = check;
  const auto materials = mesh::load_material(material, data_folder());
  if (!out.empty()) output::require_output_folder(out, "out");
  calibration::CalibrationOutcome o;
  {
    py::gil_scoped_release release;
    o = calibration::calibrate_disc(mesh, materials, rq);
  }
  const nlohmann::json tuned = calibration::to_json(o.tuned);
  if (o.success && !out.empty()) output::write_json_file(out, tuned);
  py::dict d;
  d["success"] = o.success;
  d["status"] = o.result.status;
  d["iterations"] = o.result.iterations;
  d["seconds"] = o.total_seconds;
  d["tuned"] = to_python(tuned);
  if (check) {
    d["untuned_check"] = to_python(studies::comparison_json(o.untuned_check));
    d["tuned_check"] = to_python(studies::comparison_json(o.tuned_check));
  }
  d["out"] = o.success && !out.empty() ? py::object(py::str(out)) : py::object(py::none());
  return d;
}

}  // namespace

void bind_mss(py::module_& m) {
  bind_disc(m);
  m.def("_calibrate", &calibrate);
}

}  // namespace spinesim::python
