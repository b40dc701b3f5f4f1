// `spinesim bench`'s measurements, one run each: meshing a level at a cell size, and the FEM
// reference of a mesh at an order (assembly, analysis, factorisation, the 6x6 solves, one load).
// The program runs each in a fresh process of its own, so that the peak resident memory a run
// reports (getrusage ru_maxrss) is that run's; nothing here is asserted in tests.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace spinesim::studies {

/// This process's peak resident memory so far, MB.
double peak_rss_mb();

/// Meshes `level` with CGAL at `cell_size_mm` (default options otherwise) and, when `mesh_out`
/// is given, writes it. Row: cell_size_mm, nodes, tets, seconds, min/max dihedral, volume error,
/// peak_rss_mb.
nlohmann::json bench_mesh_once(const std::string& level, double cell_size_mm,
                               const std::string& data_dir, const std::string& mesh_out = "");

/// The FEM reference (real-disc) of the mesh at `mesh_path` at `order`, then one 500 N
/// compression solve. Row: order, tets, dofs, the stage timings, load_solve_s, peak_rss_mb.
nlohmann::json bench_fem_once(const std::string& mesh_path, int order, const std::string& data_dir);

}  // namespace spinesim::studies
