#include "vtk_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace spinesim::mesh::detail {

namespace {

constexpr int kVtkTetra = 10;
constexpr int kVtkQuadraticTetra = 24;

std::string cell_type_name(std::int64_t type) {
  switch (type) {
    case 1:
      return "vertex (1)";
    case 3:
      return "line (3)";
    case 5:
      return "triangle (5)";
    case 9:
      return "quad (9)";
    case 12:
      return "hexahedron (12)";
    case 13:
      return "wedge (13)";
    case 14:
      return "pyramid (14)";
    case 22:
      return "quadratic triangle (22)";
    case 25:
      return "quadratic hexahedron (25)";
    default:
      return "VTK type " + std::to_string(type);
  }
}

Eigen::MatrixXd to_matrix(const RawArray& a) {
  const Eigen::Index rows = Eigen::Index(a.v.size()) / a.ncomp;
  Eigen::MatrixXd M(rows, a.ncomp);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (int j = 0; j < a.ncomp; ++j) M(i, j) = a.v[std::size_t(i * a.ncomp + j)];
  return M;
}

/// A PointData or CellData section of `count` tuples: the one-component integer label array
/// `label_name` goes into `labels` (left as it is when absent), every other array into `others`.
void split_section(const FileError& e, const std::vector<RawArray>& arrays, const std::string& kind,
                   std::int64_t count, const std::string& label_name, Eigen::VectorXi& labels,
                   std::vector<DataArray>& others) {
  for (const RawArray& a : arrays) {
    if (std::int64_t(a.v.size()) != count * a.ncomp)
      e.fail(kind + " '" + a.name + "' has " + std::to_string(a.v.size() / std::size_t(a.ncomp)) +
             " tuples, expected " + std::to_string(count));
    if (a.name == label_name) {
      if (a.ncomp != 1) e.fail(kind + " '" + label_name + "' must have 1 component");
      const auto s = as_integers(e, a, -2147483648.0, 2147483647.0);
      for (std::int64_t i = 0; i < count; ++i) labels(i) = int(s[std::size_t(i)]);
    } else {
      others.push_back({a.name, to_matrix(a)});
    }
  }
}

/// Moves the cell arrays `fibre_path_direction_1/2` out of `cdata` into m.fibre_paths (both
/// families or neither, 3 components each; validate() checks the lengths).
void take_fibre_paths(const FileError& e, std::vector<DataArray>& cdata, TetMesh& m) {
  Eigen::MatrixX3d* family[2] = {&m.fibre_paths.direction_1, &m.fibre_paths.direction_2};
  int found = 0;
  for (int k = 0; k < 2; ++k) {
    const auto it = std::find_if(cdata.begin(), cdata.end(),
                                 [&](const DataArray& a) { return a.name == kFibrePathArray[k]; });
    if (it == cdata.end()) continue;
    if (it->values.cols() != 3)
      e.fail(std::string("CellData '") + kFibrePathArray[k] + "' must have 3 components");
    *family[k] = it->values;
    cdata.erase(it);
    ++found;
  }
  if (found == 1)
    e.fail(std::string("CellData has one of '") + kFibrePathArray[0] + "' and '" +
           kFibrePathArray[1] + "' without the other (a fibre path needs both families)");
}

/// The cells as tetrahedra (corners of quadratic ones); returns whether any was quadratic.
bool read_cells(const FileError& e, const RawGrid& g, TetMesh& m) {
  const std::int64_t nc = g.num_cells;
  if (std::int64_t(g.offsets.size()) != nc || std::int64_t(g.types.size()) != nc)
    e.fail("Cells offsets/types have " + std::to_string(g.offsets.size()) + "/" +
           std::to_string(g.types.size()) + " entries, NumberOfCells says " + std::to_string(nc));
  for (std::int64_t v : g.connectivity)
    if (v < 0 || v >= g.num_points)
      e.fail("connectivity refers to point " + std::to_string(v) + ", the file has " +
             std::to_string(g.num_points));
  bool any_quadratic = false;
  m.T.resize(nc, 4);
  std::int64_t start = 0;
  for (std::int64_t c = 0; c < nc; ++c) {
    const std::int64_t type = g.types[std::size_t(c)];
    std::int64_t want = 0;
    if (type == kVtkTetra)
      want = 4;
    else if (type == kVtkQuadraticTetra)
      want = 10, any_quadratic = true;
    else
      e.fail("cell #" + std::to_string(c) + " is a " + cell_type_name(type) +
             "; only tetrahedra (VTK types 10 and 24) are supported");
    const std::int64_t end = g.offsets[std::size_t(c)];
    if (end - start != want || end > std::int64_t(g.connectivity.size()))
      e.fail("cell #" + std::to_string(c) + " offsets are inconsistent with its type");
    for (int k = 0; k < 4; ++k) m.T(c, k) = int(g.connectivity[std::size_t(start + k)]);
    start = end;
  }
  if (start != std::int64_t(g.connectivity.size()))
    e.fail("connectivity has " + std::to_string(g.connectivity.size()) +
           " entries, the offsets use " + std::to_string(start));
  return any_quadratic;
}

void read_field_data(const FileError& e, const RawGrid& g, TetMesh& m) {
  if (g.disc_frame) {
    const RawArray& f = *g.disc_frame;
    if (f.v.empty())
      e.fail("FieldData 'disc_frame' is empty: a VTK program (ParaView) saved this file from a "
             "spinesim file written before field arrays stated NumberOfTuples, and VTK dropped "
             "the frame; write the disc again with this spinesim and re-save it");
    if (f.v.size() != 12) e.fail("FieldData 'disc_frame' must have 12 values");
    for (double x : f.v)
      if (!std::isfinite(x)) e.fail("FieldData 'disc_frame' contains non-finite values");
    for (int i = 0; i < 3; ++i) m.frame.origin_mm(i) = f.v[std::size_t(i)];
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) m.frame.axes(i, c) = f.v[std::size_t(3 + 3 * c + i)];
  }
  if (g.source) {
    std::string text;
    for (double c : g.source->v) {
      if (c == 0) break;  // VTK String arrays are NUL-terminated
      if (c > 0 && c < 256) text += char(int(c));
    }
    if (!text.empty()) m.source = text;
  }
}

/// Quadratic tets: keep only the vertices used as corners, remap indices and point arrays.
void drop_mid_edge_nodes(TetMesh& m, std::vector<DataArray>& pdata) {
  const Eigen::Index np = m.V.rows();
  std::vector<int> new_index(std::size_t(np), -1);
  int used = 0;
  for (Eigen::Index t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      int& ni = new_index[std::size_t(m.T(t, k))];
      if (ni < 0) ni = used++;
    }
  Eigen::MatrixX3d V(used, 3);
  Eigen::VectorXi surf(used);
  for (Eigen::Index i = 0; i < np; ++i) {
    const int ni = new_index[std::size_t(i)];
    if (ni < 0) continue;
    V.row(ni) = m.V.row(i);
    surf(ni) = m.surface(i);
  }
  for (DataArray& a : pdata) {
    Eigen::MatrixXd vals(used, a.values.cols());
    for (Eigen::Index i = 0; i < np; ++i)
      if (new_index[std::size_t(i)] >= 0) vals.row(new_index[std::size_t(i)]) = a.values.row(i);
    a.values = std::move(vals);
  }
  for (Eigen::Index t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) m.T(t, k) = new_index[std::size_t(m.T(t, k))];
  m.V = std::move(V);
  m.surface = std::move(surf);
}

}  // namespace

std::vector<std::int64_t> as_integers(const FileError& e, const RawArray& a, double lo, double hi) {
  std::vector<std::int64_t> out(a.v.size());
  for (std::size_t i = 0; i < a.v.size(); ++i) {
    const double x = a.v[i];
    if (!(x >= lo && x <= hi) || x != std::floor(x))
      e.fail("'" + a.name + "' entry #" + std::to_string(i) + " = " + std::to_string(x) +
             " is not an integer in [" + std::to_string(std::int64_t(lo)) + ", " +
             std::to_string(std::int64_t(hi)) + "]");
    out[i] = std::int64_t(x);
  }
  return out;
}

TetMesh assemble_tet_mesh(const FileError& e, RawGrid g, std::vector<DataArray>* point_data,
                          std::vector<DataArray>* cell_data) {
  const std::int64_t np = g.num_points, nc = g.num_cells;
  if (np == 0 || nc == 0) e.fail("mesh is empty (NumberOfPoints or NumberOfCells is 0)");
  // 1. Points.
  if (g.points.ncomp != 3)
    e.fail("Points must have 3 components, found " + std::to_string(g.points.ncomp));
  if (std::int64_t(g.points.v.size()) != 3 * np)
    e.fail("Points has " + std::to_string(g.points.v.size() / 3) + " points, NumberOfPoints says " +
           std::to_string(np));
  for (double x : g.points.v)
    if (!std::isfinite(x)) e.fail("point coordinates contain non-finite values");
  TetMesh m;
  m.V.resize(np, 3);
  for (std::int64_t i = 0; i < np; ++i)
    for (int j = 0; j < 3; ++j) m.V(i, j) = g.points.v[std::size_t(3 * i + j)];
  // 2. Cells.
  const bool any_quadratic = read_cells(e, g, m);
  // 3. Point and cell data; FieldData: frame and provenance.
  m.surface = Eigen::VectorXi::Zero(np);
  m.region = Eigen::VectorXi::Ones(nc);
  std::vector<DataArray> pdata, cdata;
  split_section(e, g.point_data, "PointData", np, "surface", m.surface, pdata);
  split_section(e, g.cell_data, "CellData", nc, "region", m.region, cdata);
  take_fibre_paths(e, cdata, m);
  m.source = e.path;
  read_field_data(e, g, m);
  if (any_quadratic) drop_mid_edge_nodes(m, pdata);
  // 4. Geometric sanity (inverted / zero-volume tets) from the shared validator.
  try {
    validate(m);
  } catch (const std::invalid_argument& ex) {
    e.fail(ex.what());
  }
  if (point_data) *point_data = std::move(pdata);
  if (cell_data) *cell_data = std::move(cdata);
  return m;
}

VtuGrid assemble_grid(const FileError& e, const RawGrid& g) {
  const std::int64_t np = g.num_points, nc = g.num_cells;
  if (np == 0 || nc == 0) e.fail("mesh is empty (NumberOfPoints or NumberOfCells is 0)");
  if (g.points.ncomp != 3 || std::int64_t(g.points.v.size()) != 3 * np)
    e.fail("Points must hold NumberOfPoints points of 3 components");
  VtuGrid out;
  out.V.resize(np, 3);
  for (std::int64_t i = 0; i < np; ++i)
    for (int j = 0; j < 3; ++j) {
      const double x = g.points.v[std::size_t(3 * i + j)];
      if (!std::isfinite(x)) e.fail("point coordinates contain non-finite values");
      out.V(i, j) = x;
    }
  if (std::int64_t(g.offsets.size()) != nc || std::int64_t(g.types.size()) != nc)
    e.fail("Cells offsets/types do not match NumberOfCells");
  const std::int64_t type = g.types.front();
  if (type != kVtkTetra && type != 5)
    e.fail("cell #0 is a " + cell_type_name(type) + "; only tetrahedra (10) or triangles (5)");
  const int corners = type == kVtkTetra ? 4 : 3;
  out.cell_type = int(type);
  out.cells.resize(nc, corners);
  for (std::int64_t c = 0; c < nc; ++c)
    if (g.types[std::size_t(c)] != type)
      e.fail("cell #" + std::to_string(c) + " is a " + cell_type_name(g.types[std::size_t(c)]) +
             ", cell #0 a " + cell_type_name(type) + ": one kind of cell only");
  if (std::int64_t(g.connectivity.size()) != corners * nc)
    e.fail("connectivity has " + std::to_string(g.connectivity.size()) + " entries, expected " +
           std::to_string(corners * nc));
  for (std::int64_t c = 0; c < nc; ++c) {
    if (g.offsets[std::size_t(c)] != corners * (c + 1))
      e.fail("cell #" + std::to_string(c) + " offsets are inconsistent with its type");
    for (int k = 0; k < corners; ++k) {
      const std::int64_t v = g.connectivity[std::size_t(corners * c + k)];
      if (v < 0 || v >= np) e.fail("connectivity refers to a point out of range");
      out.cells(c, k) = int(v);
    }
  }
  const auto arrays = [&](const std::vector<RawArray>& in, std::int64_t count, const char* kind,
                          std::vector<DataArray>& to) {
    for (const RawArray& a : in) {
      if (std::int64_t(a.v.size()) != count * a.ncomp)
        e.fail(std::string(kind) + " '" + a.name + "' has the wrong number of tuples");
      for (double x : a.v)
        if (!std::isfinite(x)) e.fail(std::string(kind) + " '" + a.name + "' is not finite");
      to.push_back({a.name, to_matrix(a)});
    }
  };
  arrays(g.point_data, np, "PointData", out.point_data);
  arrays(g.cell_data, nc, "CellData", out.cell_data);
  return out;
}

}  // namespace spinesim::mesh::detail
