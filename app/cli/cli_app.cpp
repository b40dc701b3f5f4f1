#include "cli_common.hpp"
#include "study_file.hpp"

#include "spinesim/common/build_info.hpp"

namespace spinesim::cli {

std::unique_ptr<CLI::App> make_app() {
  auto app = std::make_unique<CLI::App>(
      "spinesim: finite-element-validated intervertebral-disc deformation\n"
      "(CGAL disc meshes, linear FEM reference, mass-spring discs, spine model)");
  app->set_version_flag("--version", std::string("spinesim ") + build_version() + " (commit " +
                                         build_commit() + ")");
  app->require_subcommand(1);
  register_mesh(*app);
  register_fem(*app);
  register_export(*app);
  register_mss(*app);
  register_calibrate(*app);
  register_spine(*app);
  register_study(*app);
  register_haptics(*app);
  register_demo(*app);
  register_view(*app);
  register_bench(*app);
  register_run(*app);
  register_sweep(*app);
  add_save_study_options(*app);
  require_plain_numbers(*app);
  return app;
}

}  // namespace spinesim::cli
