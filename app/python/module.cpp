// The module `spinesim._spinesim`: the compiled half of the Python package (spinesim/__init__.py
// is the other: keyword arguments, defaults, results as attribute dictionaries).
#include "bindings.hpp"
#include "cli_main.hpp"

#include "spinesim/common/provenance.hpp"
#include "spinesim/studies/data.hpp"

#include <pybind11/stl.h>

#include <cstdlib>
#include <iostream>
#include <sstream>

// One OpenBLAS thread under CHOLMOD unless the user sets OPENBLAS_NUM_THREADS, as the program
// does (app/cli/main.cpp): faster on small machines, and the same numbers as the program's.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace spinesim::python {
namespace {

/// The script's command line (sys.argv), recorded again after a `main` or `run_study` call has
/// recorded its own: outputs the script writes itself then name the script.
std::vector<std::string>& script_command() {
  static std::vector<std::string> argv{"python3"};
  return argv;
}

void record_script() {
  std::vector<const char*> argv;
  for (const auto& a : script_command()) argv.push_back(a.c_str());
  record_run_command(int(argv.size()), argv.data());
}

/// Runs `f` with std::cout going into a string (the verb's printed output); returns it.
template <class F>
std::string captured_stdout(F&& f) {
  std::ostringstream text;
  std::streambuf* old = std::cout.rdbuf(text.rdbuf());
  try {
    f();
  } catch (...) {
    std::cout.rdbuf(old);
    record_script();
    throw;
  }
  std::cout.rdbuf(old);
  record_script();
  return text.str();
}

}  // namespace

py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

std::string data_folder() { return studies::data_dir(); }

void bind_cli(py::module_& m) {
  m.def(
      "_record_script",
      [](const std::vector<std::string>& argv) {
        script_command() = argv;
        record_script();
      },
      "Records the script's command line as the provenance of what it writes");
  m.def(
      "main",
      [](const std::vector<std::string>& args) {
        std::cout.flush();
        const int status = cli::run_command_line(args);
        std::cout.flush();
        record_script();
        return status;
      },
      py::arg("args"), py::call_guard<py::gil_scoped_release>(),
      R"(Runs one spinesim command line in this process, as the program would:
spinesim.main(["fem", "--mesh", "disc.vtu", "--case", "flexion"]). Prints to the process's
stdout and stderr; returns the exit status (0, or 1 with the error on stderr).)");
  m.def(
      "_execute",
      [](const std::vector<std::string>& args) {
        py::gil_scoped_release release;
        return captured_stdout([&] { cli::execute_command_line(args); });
      },
      py::arg("args"));
  m.def("data_dir", &data_folder, "The folder of the shipped presets and tables");
}

}  // namespace spinesim::python

PYBIND11_MODULE(_spinesim, m) {
  m.doc() = "spinesim's drivers (C++): use the package `spinesim`";
  if (openblas_set_num_threads && !std::getenv("OPENBLAS_NUM_THREADS")) openblas_set_num_threads(1);
  m.attr("built_for_python") = pybind11::make_tuple(PY_MAJOR_VERSION, PY_MINOR_VERSION);
  using namespace spinesim::python;
  bind_mesh(m);
  bind_fem(m);
  bind_mss(m);
  bind_spine(m);
  bind_cli(m);
}
