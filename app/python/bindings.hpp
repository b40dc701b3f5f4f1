// The Python module `spinesim` (pybind11): the study drivers with NumPy arrays in and out.
// Each bind_*.cpp adds one group of functions; module.cpp puts them together.
#pragma once

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include <string>

namespace spinesim::python {

namespace py = pybind11;

/// A JSON value as the Python value json.loads would give.
py::object to_python(const nlohmann::json& j);

/// The data folder the drivers read presets and tables from (studies::data_dir()).
std::string data_folder();

void bind_mesh(py::module_& m);   ///< Mesh, read_mesh, mesh_disc (bind_mesh.cpp)
void bind_fem(py::module_& m);    ///< fem, load_cases (bind_fem.cpp)
void bind_mss(py::module_& m);    ///< MassSpringDisc, Simulation, calibrate (bind_mss.cpp)
void bind_spine(py::module_& m);  ///< spine, seated_spine (bind_spine.cpp)
void bind_cli(py::module_& m);    ///< main, run_study (module.cpp)

}  // namespace spinesim::python
