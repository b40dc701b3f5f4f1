// Private to mesh/: what the VTK readers (XML .vtu and legacy .vtk) share once their arrays are
// decoded — the raw unstructured grid, and its checked assembly into a TetMesh.
#pragma once

#include "spinesim/mesh/io.hpp"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::mesh::detail {

/// Throws std::invalid_argument "<who>: <path>: <message>" (one line).
struct FileError {
  std::string who, path;
  [[noreturn]] void fail(const std::string& msg) const {
    throw std::invalid_argument(who + ": " + path + ": " + msg);
  }
};

/// A data array decoded to doubles (exact for every integer below 2^53 and every Float64).
struct RawArray {
  std::string name;
  int ncomp = 1;
  std::vector<double> v;
};

/// An unstructured grid as a file stores it.
struct RawGrid {
  std::int64_t num_points = 0, num_cells = 0;
  RawArray points;                         ///< 3 components
  std::vector<std::int64_t> connectivity;  ///< point indices, cell after cell
  std::vector<std::int64_t> offsets;       ///< #cells: end of each cell in `connectivity`
  std::vector<std::int64_t> types;         ///< #cells: VTK cell types
  std::vector<RawArray> point_data, cell_data;
  std::optional<RawArray> disc_frame, source;  ///< FieldData written by write_vtu
};

/// Integer view of an array that must hold integers in [lo, hi].
std::vector<std::int64_t> as_integers(const FileError& e, const RawArray& a, double lo, double hi);

/// Checks the grid and builds the mesh (the read_vtu contract in io.hpp): tetrahedra only
/// (quadratic ones by their corners), `surface`/`region` labels, the other arrays out, frame and
/// source from FieldData, then validate().
TetMesh assemble_tet_mesh(const FileError& e, RawGrid grid, std::vector<DataArray>* point_data,
                          std::vector<DataArray>* cell_data);

/// Checks the grid (one cell kind: tetrahedra or triangles; finite points; array lengths) and
/// keeps it as stored: the read_vtu_grid contract in io.hpp.
VtuGrid assemble_grid(const FileError& e, const RawGrid& grid);

}  // namespace spinesim::mesh::detail
