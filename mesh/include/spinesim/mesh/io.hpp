// Mesh and result files: VTU (VTK XML UnstructuredGrid), Medit .mesh, and surface meshes.
//
// VTU layout (docs/cli.md), written as VTKFile version 1.0, LittleEndian, header_type UInt64:
//   - Points: Float64 ×3, mm, full precision (binary is bit-exact; ASCII uses the shortest
//     round-trip decimal form, so it is exact too);
//   - Cells: connectivity/offsets Int64, types UInt8 = 10 (VTK_TETRA);
//   - CellData `region` (Int32), the mesh's fibre paths when it has any
//     (`fibre_path_direction_1/2`, Float64 ×3), then the caller's cell arrays (Float64);
//   - PointData `surface` (Int32) then the caller's point arrays (Float64, NumberOfComponents =
//     columns), e.g. `displacement`, 3 components, mm;
//   - FieldData (always ASCII, with NumberOfTuples, which VTK needs to size a field array)
//     `disc_frame`: one tuple of 12 Float64 = origin (mm), then the 3 columns of
//     `axes` (lateral, axial, anterior); and `source`: the provenance string as UInt8 character
//     codes (not VTK's String type, which meshio cannot read).
// Writers refuse bad input (non-finite values, wrong array sizes) before touching the disk, write
// to `path + ".tmp-XXXXXX"` in the same folder and rename it over `path`, so a failure never
// leaves a partial file or a stray temporary; a file already at `path` is replaced only by a
// complete new one (after a refused write it is left as it was). User-input problems throw
// std::invalid_argument; operating-system failures (folder missing, disk full) throw
// std::runtime_error. All messages are one line and name the file.
#pragma once

#include "spinesim/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace spinesim::mesh {

/// The cell arrays that carry TetMesh::fibre_paths in a VTU (read and written with the mesh).
inline constexpr const char* kFibrePathArray[2] = {"fibre_path_direction_1",
                                                   "fibre_path_direction_2"};

/// A named point- or cell-data array: #rows × ncomponents (rows = #V for point data, #T for
/// cell data).
struct DataArray {
  std::string name;
  Eigen::MatrixXd values;
};

/// A triangle surface (vertebra, endplate patch).
struct TriSurface {
  Eigen::MatrixX3d V;  ///< #V×3, mm, spinesim frame
  Eigen::MatrixX3i F;  ///< #F×3, 0-based vertex indices
};

/// How VTU DataArrays are encoded: inline base64 raw binary (compact, bit-exact; default),
/// ASCII text (human readable, also exact), or inline base64 binary compressed in 32 KiB zlib
/// blocks (VTK's vtkZLibDataCompressor; bit-exact, for long time series).
enum class VtuEncoding { binary, ascii, zlib };

struct VtuWriteOptions {
  VtuEncoding encoding = VtuEncoding::binary;
};

/// Writes `m` and the extra arrays to `path` (layout above). Names `surface`, `region` and
/// `fibre_path_direction_1/2` are reserved. Throws std::invalid_argument "... contains non-finite values" for NaN/Inf in the
/// coordinates or any array, and for label/array size mismatches or indices out of range;
/// nothing is written then.
void write_vtu(const std::string& path, const TetMesh& m,
               const std::vector<DataArray>& point_data = {},
               const std::vector<DataArray>& cell_data = {}, const VtuWriteOptions& options = {});

/// Writes a triangle surface as a VTU (VTK_TRIANGLE cells) with extra point and cell arrays —
/// the vertebrae beside the discs of a time series. Same checks, encoding and atomic write as
/// write_vtu (no reserved names; indices must be in range).
void write_surface_vtu(const std::string& path, const TriSurface& s,
                       const std::vector<DataArray>& point_data = {},
                       const std::vector<DataArray>& cell_data = {},
                       const VtuWriteOptions& options = {});

/// Reads a VTU with a single Piece, in every encoding the VTK XML format allows: DataArrays
/// format="ascii", "binary" (inline base64) or "appended" (<AppendedData> raw or base64, arrays
/// located by their offsets); header_type UInt32 or UInt64; uncompressed, or compressed with
/// vtkZLibDataCompressor, vtkLZ4DataCompressor or vtkLZMADataCompressor (VTK's block header: #blocks, block size,
/// last block size, compressed sizes); any VTK numeric type, either byte order. A file whose
/// header announces more than 4 GiB for one array is refused (corrupt or hostile).
/// Cells: VTK_TETRA (10); VTK_QUADRATIC_TETRA (24) is read by its 4 corner vertices and
/// vertices used only as mid-edge nodes are dropped (indices and point arrays are remapped).
/// Any other cell type is an error naming it. Missing `region` -> all 1; missing `surface` ->
/// all 0 (fem then refuses: no endplate labels). `disc_frame` and `source` FieldData fill
/// m.frame and m.source when present (else identity frame and the file name); CellData
/// `fibre_path_direction_1/2` (both or neither, 3 components) fill m.fibre_paths.
/// The other PointData arrays go to `point_data`, the other CellData arrays to `cell_data`
/// (when non-null). Finally calls validate(m), so inverted/zero-volume tets are reported.
/// Throws std::invalid_argument with one line "read_vtu: PATH: problem" for any bad file.
TetMesh read_vtu(const std::string& path, std::vector<DataArray>* point_data = nullptr,
                 std::vector<DataArray>* cell_data = nullptr);

/// A VTU as stored, for playing a time series back: points, cells of one kind and every data
/// array (`region` and `surface` too), with no geometric checks (a deformed frame may hold
/// inverted tetrahedra).
struct VtuGrid {
  Eigen::MatrixX3d V;     ///< #V×3
  Eigen::MatrixXi cells;  ///< #C×4 (tetrahedra) or #C×3 (triangles)
  int cell_type = 0;      ///< 10 (VTK_TETRA) or 5 (VTK_TRIANGLE)
  std::vector<DataArray> point_data, cell_data;
  /// The array called `name` (nullptr when absent).
  const DataArray* point_array(const std::string& name) const;
  const DataArray* cell_array(const std::string& name) const;
};

/// Reads a VTU as read_vtu does (every encoding), holding only tetrahedra or only triangles.
/// Throws std::invalid_argument "read_vtu: PATH: problem" (one line) for a bad file, mixed or
/// other cell types, non-finite coordinates or arrays of the wrong length.
VtuGrid read_vtu_grid(const std::string& path);

/// Reads a legacy VTK unstructured grid (.vtk): ASCII or BINARY (big-endian), file versions
/// up to 4.2 (CELLS as "count ids…" lists) and 5.1 (OFFSETS + CONNECTIVITY); POINT_DATA and
/// CELL_DATA as SCALARS, VECTORS, NORMALS, TENSORS or FIELD arrays; dataset FIELD data
/// `disc_frame` and `source` as in a VTU. The same cell rules and checks as read_vtu; messages
/// "read_vtk: PATH: problem".
TetMesh read_vtk_legacy(const std::string& path, std::vector<DataArray>* point_data = nullptr,
                        std::vector<DataArray>* cell_data = nullptr);

/// A tetrahedral mesh file of either kind: legacy VTK when it starts with "# vtk DataFile
/// Version", else VTU. What the program's --mesh options read.
TetMesh read_tet_mesh(const std::string& path, std::vector<DataArray>* point_data = nullptr,
                      std::vector<DataArray>* cell_data = nullptr);

/// Medit .mesh (ASCII, MeshVersionFormatted 2, Dimension 3): Vertices with the surface label as
/// reference, Tetrahedra (1-based) with the region label, and the boundary Triangles (faces used
/// by exactly one tet, oriented outward) with reference = the label shared by all three vertices
/// when it is nonzero (1 or 2 for an endplate triangle), else 3 (outer wall). A wall triangle
/// whose three vertices all lie on one endplate rim would be labelled as endplate: with Mesh_3
/// discs such triangles are rare and sit on the rim. Atomic write as for write_vtu.
void write_medit(const std::string& path, const TetMesh& m);

/// The file's axis that points superior (up).
enum class UpAxis { x, y, z, minus_x, minus_y, minus_z };

/// Reads STL (ASCII or binary), OBJ, PLY or OFF, chosen by extension (any letter case), as a
/// polygon soup (it need not be closed or manifold; OBJ normals/texture coordinates are
/// ignored). Polygons with more than 3 vertices are fan-triangulated; polygons with fewer are
/// an error. Coordinates are multiplied by `units_to_mm` (1 for mm, 1000 for m), then mapped
/// into the spinesim frame (x lateral, y up, z anterior) by a rotation that sends `up` to +y:
///   up = y:        (x, y, z)_file -> ( x,  y,  z)   (identity)
///   up = z:        (x, y, z)_file -> ( y,  z,  x)   (cyclic: file x becomes anterior)
///   up = x:        (x, y, z)_file -> ( z,  x,  y)   (cyclic: file y becomes anterior)
///   up = minus_a:  the map for `a`, followed by a 180° rotation about the lateral axis,
///                  (x, y, z) -> (x, -y, -z); e.g. minus_z: (x, y, z)_file -> (y, -z, -x).
/// All maps are proper rotations (determinant +1), so the orientation of triangles is kept.
/// For the ArtiSynth lumbar surfaces (metres, z up, x anterior) `units_to_mm = 1000, up = z`
/// gives anterior = +z directly.
/// Throws std::invalid_argument with one line "read_surface: PATH: problem" for a missing file,
/// unknown extension, unreadable or empty file (no triangles), face index out of range or
/// non-finite coordinates; also for units_to_mm that is not finite and positive.
TriSurface read_surface(const std::string& path, double units_to_mm, UpAxis up);

/// The rotation read_surface applies: a point in file coordinates (already in mm) in the
/// spinesim frame.
Eigen::Vector3d to_spinesim_frame(const Eigen::Vector3d& p, UpAxis up);

/// One dataset of a ParaView data collection: the time it shows (s), its file and the part it
/// belongs to (a collection of several parts shows them together at each time: discs and
/// vertebrae, say). A relative `file` is resolved by ParaView against the .pvd file's folder.
struct PvdEntry {
  double time_s = 0.0;
  std::string file;
  int part = 0;  ///< >= 0
};

/// Writes a ParaView data collection (.pvd: VTKFile type="Collection", one
/// <DataSet timestep=".." group="" part=".." file=".."/> per entry, times in the shortest
/// round-trip decimal form, names XML-escaped) — the time series of VTU frames. Refuses
/// (std::invalid_argument, one line naming `path`) an empty list, a negative part, non-finite
/// times or times not strictly increasing within a part, and empty file names; the listed files
/// need not exist yet. Atomic write as for write_vtu.
void write_pvd(const std::string& path, const std::vector<PvdEntry>& entries);

/// Reads a ParaView data collection: its <DataSet> entries in file order, each `file` resolved
/// against the .pvd's folder. Throws std::invalid_argument "read_pvd: PATH: problem" (one line)
/// for a missing or unreadable file, no entries, a bad timestep or part, an empty file name, or
/// times not strictly increasing within a part. The listed files are not opened.
std::vector<PvdEntry> read_pvd(const std::string& path);

}  // namespace spinesim::mesh
