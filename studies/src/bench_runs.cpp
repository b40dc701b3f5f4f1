#include "spinesim/studies/bench_runs.hpp"

#include "spinesim/common/timer.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/disc_geometry.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/mesher.hpp"
#include "spinesim/mesh/quality.hpp"

#include <sys/resource.h>

#include <stdexcept>

namespace spinesim::studies {

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // Linux reports KiB
}

nlohmann::json bench_mesh_once(const std::string& level, double cell_size_mm,
                               const std::string& data_dir, const std::string& mesh_out) {
  if (!(cell_size_mm > 0)) throw std::invalid_argument("--cell-size must be > 0 mm");
  const auto dims = mesh::disc_dimensions(level, data_dir);
  mesh::MeshOptions opt;
  opt.cell_size_mm = cell_size_mm;
  const Timer t0;
  const auto m = mesh::mesh_parametric_disc(dims, opt);
  const double s = t0.seconds();
  const auto q = mesh::quality_report(m, mesh::parametric_disc_volume(dims));
  if (!mesh_out.empty()) mesh::write_vtu(mesh_out, m);
  return {{"cell_size_mm", cell_size_mm},
          {"nodes", q.vertices},
          {"tets", q.tets},
          {"seconds", s},
          {"min_dihedral_deg", q.min_dihedral_deg},
          {"max_dihedral_deg", q.max_dihedral_deg},
          {"volume_error", q.volume_error()},
          {"peak_rss_mb", peak_rss_mb()}};
}

nlohmann::json bench_fem_once(const std::string& mesh_path, int order,
                              const std::string& data_dir) {
  const auto m = mesh::read_tet_mesh(mesh_path);
  const double rss_mesh = peak_rss_mb();
  const auto mat = mesh::load_material("real-disc", data_dir);
  const Timer t0;
  const fem::DiscFem solver(m, mat, order, fem::DiscFem::default_plate_center(m));
  const double stiffness_s = t0.seconds();
  fem::Vector6d w = fem::Vector6d::Zero();
  w(1) = -500.0;
  const Timer t1;
  (void)solver.solve_wrench(w);
  const double load_s = t1.seconds();
  const auto& t = solver.timings();
  return {{"order", order},
          {"tets", m.num_tets()},
          {"dofs", solver.num_dofs()},
          {"setup_s", t.setup_s},
          {"assembly_s", t.assembly_s},
          {"analyse_s", t.analyse_s},
          {"factorise_s", t.factorise_s},
          {"stiffness_solves_s", t.solve_s},
          {"stiffness_total_s", stiffness_s},
          {"load_solve_s", load_s},
          {"peak_rss_mb", peak_rss_mb()},
          {"rss_after_mesh_read_mb", rss_mesh}};
}

}  // namespace spinesim::studies
