// spinesim.fem, spinesim.load_cases, spinesim.export_abaqus, spinesim.export_febio.
#include "bindings.hpp"

#include "spinesim/fem/load_cases.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/studies/fem_reference.hpp"
#include "spinesim/studies/nonlinear_fem_run.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>

namespace spinesim::python {
namespace {

/// A named array as NumPy: one column as a vector, more as a matrix.
py::object array(const mesh::DataArray& a) {
  if (a.values.cols() == 1) return py::cast(Eigen::VectorXd(a.values.col(0)));
  return py::cast(a.values);
}

studies::FemRunRequest fem_request(const std::string& load_case,
                                   const std::optional<fem::Vector6d>& motion_deg,
                                   const std::optional<fem::Vector6d>& wrench,
                                   const std::optional<Eigen::Vector3d>& center, int order,
                                   const std::string& formulation) {
  studies::FemRunRequest rq;
  rq.order = order;
  rq.formulation = studies::parse_formulation(formulation);
  if (motion_deg) rq.motion = studies::motion_deg_to_rad(*motion_deg);
  rq.wrench = wrench;
  rq.center = center;
  if (!load_case.empty()) rq.load_case = &fem::load_case(load_case);
  return rq;
}

py::dict fem_solve(const mesh::TetMesh& m, const std::string& material,
                   const studies::FemRunRequest& rq, const std::string& out) {
  const mesh::RegionMaterials materials = mesh::load_material(material, data_folder());
  studies::FemRunResult r;
  {
    py::gil_scoped_release release;
    mesh::validate(m);
    mesh::require_endplate_labels(m);
    r = studies::run_fem_reference(m, materials, rq);
    if (!out.empty()) studies::write_fem_vtu(out, m, r);
  }
  const studies::FemArrays arrays = studies::fem_run_arrays(m, r);
  py::dict point_data, fields;
  for (const auto& a : arrays.points) point_data[py::str(a.name)] = array(a);
  for (const auto& a : arrays.cells) fields[py::str(a.name)] = array(a);
  nlohmann::json summary = studies::fem_run_json(r, m.source);
  if (!out.empty()) summary["out"] = out;
  py::dict d;
  d["displacement_mm"] = r.solution.displacement_mm;
  d["plate_motion_deg"] = fem::Vector6d(studies::motion_rad_to_deg(r.solution.plate_motion));
  d["reaction_wrench"] = r.solution.reaction_wrench;
  d["stiffness_per_deg"] = fem::Matrix6d(studies::stiffness_per_degree(r.stiffness));
  d["point_data"] = point_data;
  d["fields"] = fields;
  d["summary"] = to_python(summary);
  return d;
}

py::dict fem_nonlinear(const mesh::TetMesh& m, const std::string& material,
                       const studies::FemRunRequest& rq, int increments, const std::string& out) {
  const mesh::RegionMaterials materials = mesh::load_material(material, data_folder());
  studies::NonlinearFemRun r;
  {
    py::gil_scoped_release release;
    mesh::validate(m);
    r = studies::run_nonlinear_fem(m, materials, rq, increments);
    if (!out.empty()) studies::write_nonlinear_fem_vtu(out, m, r);
  }
  const fem::NonlinearElementFields& f = r.fields;
  py::dict fields;
  fields["cauchy_stress_MPa"] = f.cauchy_stress_mpa;
  fields["von_mises_MPa"] = f.von_mises_mpa;
  fields["pressure_MPa"] = f.pressure_mpa;
  fields["green_lagrange_strain"] = f.green_lagrange_strain;
  fields["principal_stretch"] = f.principal_stretch;
  for (int k = 0; k < 3; ++k)
    fields[py::str("principal_stretch_direction_" + std::to_string(k + 1))] =
        Eigen::MatrixX3d(f.principal_stretch_directions.middleCols(3 * k, 3));
  fields["fibre_stretch"] = f.fibre_stretch;
  fields["fibre_stress_MPa"] = f.fibre_stress_mpa;
  fields["volume_ratio"] = f.volume_ratio;
  fields["strain_energy_density_MPa"] = f.strain_energy_density_mpa;
  nlohmann::json summary = studies::nonlinear_fem_json(r, m.source, materials.name);
  if (!out.empty()) summary["out"] = out;
  py::dict d;
  d["displacement_mm"] = Eigen::MatrixX3d(r.solution.body.displacement_mm.topRows(m.num_vertices()));
  d["plate_motion_deg"] = fem::Vector6d(studies::motion_rad_to_deg(r.solution.plate_motion));
  d["reaction_wrench"] = r.solution.reaction_wrench;
  d["fields"] = fields;
  d["summary"] = to_python(summary);
  return d;
}

}  // namespace

void bind_fem(py::module_& m) {
  m.def(
      "load_cases",
      [] {
        std::vector<std::string> names;
        for (const auto& c : fem::standard_load_cases()) names.push_back(c.name);
        return names;
      },
      "The named load cases (compression, tension, shear-ap, shear-lat, flexion, extension, "
      "lateral-bending, torsion)");

  m.def(
      "_fem",
      [](const mesh::TetMesh& mesh, const std::string& material, const std::string& load_case,
         const std::optional<fem::Vector6d>& motion_deg, const std::optional<fem::Vector6d>& wrench,
         const std::optional<Eigen::Vector3d>& center, int order, const std::string& formulation,
         const std::string& out) {
        return fem_solve(mesh, material,
                         fem_request(load_case, motion_deg, wrench, center, order, formulation), out);
      },
      py::arg("mesh"), py::arg("material"), py::arg("case"), py::arg("motion_deg"),
      py::arg("wrench"), py::arg("center"), py::arg("order"), py::arg("formulation"),
      py::arg("out"));

  m.def(
      "_fem_nonlinear",
      [](const mesh::TetMesh& mesh, const std::string& material, const std::string& load_case,
         const std::optional<fem::Vector6d>& motion_deg, const std::optional<fem::Vector6d>& wrench,
         const std::optional<Eigen::Vector3d>& center, int order, int increments,
         const std::string& out) {
        return fem_nonlinear(
            mesh, material,
            fem_request(load_case, motion_deg, wrench, center, order, "displacement"), increments,
            out);
      });

  m.def(
      "_export_abaqus",
      [](const std::string& path, const mesh::TetMesh& mesh, const std::string& material,
         const std::string& load_case, const std::optional<fem::Vector6d>& motion_deg,
         const std::optional<fem::Vector6d>& wrench, const std::optional<Eigen::Vector3d>& center,
         int order) {
        const auto materials = mesh::load_material(material, data_folder());
        const studies::DeckExport e = studies::export_abaqus_deck(
            path, mesh, materials,
            fem_request(load_case, motion_deg, wrench, center, order, "displacement"),
            mesh.source + ", material " + materials.name + " (spinesim, Python)");
        return e.element;
      });

  m.def(
      "_export_febio",
      [](const std::string& path, const mesh::TetMesh& mesh, const std::string& material,
         const std::string& load_case, const std::optional<fem::Vector6d>& motion_deg,
         const std::optional<fem::Vector6d>& wrench, const std::optional<Eigen::Vector3d>& center,
         int order) {
        const auto materials = mesh::load_material(material, data_folder());
        studies::FebioExport e;
        {
          py::gil_scoped_release release;
          e = studies::export_febio_deck(
              path, mesh, materials,
              fem_request(load_case, motion_deg, wrench, center, order, "displacement"),
              mesh.source + ", material " + materials.name + " (spinesim, Python)");
        }
        py::dict d;
        d["element"] = e.element;
        d["plate_motion_deg"] = fem::Vector6d(studies::motion_rad_to_deg(e.motion));
        d["plate_center_mm"] = e.center;
        return d;
      });
}

}  // namespace spinesim::python
