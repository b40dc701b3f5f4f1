// Mesh and result files: VTU (VTK XML UnstructuredGrid), Medit .mesh, and surface meshes.
//
// VTU layout (SPEC "mesh/"): points in mm; CellData `region` (Int32); PointData `surface`
// (Int32) and any extra point arrays (e.g. `displacement`, 3 components, mm); FieldData
// `disc_frame` (12 Float64: origin, then the 3 axes as columns) when the frame is known.
// Writers write to a temporary file and rename it, so a failure never leaves a partial file.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// A named point- or cell-data array: #rows × ncomponents.
struct DataArray {
  std::string name;
  Eigen::MatrixXd values;
};

void write_vtu(const std::string& path, const TetMesh& m,
               const std::vector<DataArray>& point_data = {},
               const std::vector<DataArray>& cell_data = {});

/// Reads linear tets (VTK type 10) from ASCII or raw-binary base64 VTU (UInt32/UInt64 headers,
/// no compression). Quadratic tets (type 24) are read by their 4 corner vertices. Missing
/// `region` -> all 1; missing `surface` -> all 0 (fem then refuses: no endplate labels).
/// Throws std::invalid_argument with a one-line message for a missing or corrupt file.
TetMesh read_vtu(const std::string& path, std::vector<DataArray>* point_data = nullptr);

/// Medit .mesh (Vertices with surface label as reference, Tetrahedra with region label,
/// boundary Triangles with the surface label).
void write_medit(const std::string& path, const TetMesh& m);

/// A triangle surface (vertebra, endplate patch).
struct TriSurface {
  Eigen::MatrixX3d V;  ///< #V×3, mm, spinesim frame
  Eigen::MatrixX3i F;  ///< #F×3
};

enum class UpAxis { x, y, z, minus_x, minus_y, minus_z };

/// Reads STL/OBJ/PLY/OFF (by extension), scales by `units_to_mm` (1 for mm, 1000 for m) and
/// rotates so that `up` becomes +y (right-handed; for up = z: (x,y,z) -> (y, z, x)... see
/// io.cpp for the exact map). Throws std::invalid_argument for missing/empty/corrupt files.
TriSurface read_surface(const std::string& path, double units_to_mm, UpAxis up);

}  // namespace spinesim::mesh
