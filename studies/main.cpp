// spinesim — finite-element-validated intervertebral-disc deformation.
//
//   spinesim mesh disc --level L4-L5 --out disc.vtu
//   spinesim fem --mesh disc.vtu --material real-disc --motion 0,-0.1,0,0,0,0
//   spinesim demo --out demo-out
//
// Every verb has --help and --json (one JSON object on stdout). Bad input: one line on
// stderr, exit status 1 (2 for a malformed command line), no partial output file.
#include "cli_common.hpp"

#include <iostream>

int main(int argc, char** argv) {
  CLI::App app{"spinesim: finite-element-validated intervertebral-disc deformation\n"
               "(CGAL disc meshes, linear FEM reference, mass-spring discs, spine model)"};
  app.set_version_flag("--version", std::string("spinesim ") + SPINESIM_VERSION);
  app.require_subcommand(1);
  spinesim::cli::register_mesh(app);
  spinesim::cli::register_fem(app);
  spinesim::cli::register_demo(app);
  spinesim::cli::register_bench(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "spinesim: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
