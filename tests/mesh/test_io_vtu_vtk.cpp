// VTU files against VTK itself (Debian's python3-vtk9, the library ParaView reads and writes
// with): VTK reads every array we write, field data included, value for value; and we read
// every encoding VTK writes — inline ASCII and base64, appended raw and base64; uncompressed,
// zlib, LZ4 and LZMA; UInt32 and UInt64 headers — back to the same mesh, frame and fields.
#include "spinesim/mesh/io.hpp"

#include "io_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>
#include <vector>

using namespace spinesim::mesh;
using nlohmann::json;

namespace {

bool has_vtk() { return test::python_has("vtk, numpy"); }

/// The cube with a turned, offset frame, a source that needs XML escaping and awkward field
/// values: a 3-vector at the points, a symmetric tensor (6) and a unit vector (3) per cell.
struct Fixture {
  TetMesh mesh;
  std::vector<DataArray> point, cell;
};

Fixture fixture() {
  Fixture f;
  f.mesh = test::kuhn_cube_mesh();
  f.mesh.frame.origin_mm << 1.5, -2.25, 1e-7;
  f.mesh.frame.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  f.mesh.source = "VTK round trip <&> \"cube\"";
  Eigen::MatrixXd u(f.mesh.num_vertices(), 3), p(f.mesh.num_vertices(), 1);
  for (Eigen::Index i = 0; i < u.rows(); ++i) {
    u.row(i) << std::sin(1.0 + double(i)) / 3.0, -1e-300 * double(i), 1e17 / (1.0 + double(i));
    p(i) = std::sqrt(2.0) * double(i) - 0.1;
  }
  Eigen::MatrixXd s(f.mesh.num_tets(), 6), a(f.mesh.num_tets(), 3);
  for (Eigen::Index t = 0; t < s.rows(); ++t) {
    for (int k = 0; k < 6; ++k) s(t, k) = std::exp(0.37 * double(t + k)) - 2.0 / 3.0;
    a.row(t) = Eigen::RowVector3d(1.0, double(t), -0.5).normalized();
  }
  f.point = {{"displacement_mm", u}, {"pressure_MPa", p}};
  f.cell = {{"stress_MPa", s}, {"fibre_direction", a}};
  return f;
}

/// VTK reads a VTU and prints every array (field, point and cell data, points, cells) as JSON;
/// Python's float repr round-trips, so the numbers compare exactly.
const char* kVtkDump = R"PY(
import sys, json, vtk
from vtk.util.numpy_support import vtk_to_numpy
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
if r.GetErrorCode() != 0:
    sys.exit("VTK could not read " + sys.argv[1])
g = r.GetOutput()
def arrays(d):
    out = {}
    for i in range(d.GetNumberOfArrays()):
        a = d.GetAbstractArray(i)
        out[a.GetName()] = {"tuples": a.GetNumberOfTuples(), "components": a.GetNumberOfComponents(),
                            "values": [float(x) for x in vtk_to_numpy(a).ravel()]}
    return out
cells = g.GetCells()
print(json.dumps({
    "points": [float(x) for x in vtk_to_numpy(g.GetPoints().GetData()).ravel()],
    "connectivity": [int(x) for x in vtk_to_numpy(cells.GetConnectivityArray())],
    "types": [int(g.GetCellType(i)) for i in range(g.GetNumberOfCells())],
    "field": arrays(g.GetFieldData()), "point": arrays(g.GetPointData()), "cell": arrays(g.GetCellData())}))
)PY";

/// Row-major values of a matrix, as VTK stores tuples.
std::vector<double> flat(const Eigen::MatrixXd& M) {
  std::vector<double> v;
  for (Eigen::Index i = 0; i < M.rows(); ++i)
    for (Eigen::Index j = 0; j < M.cols(); ++j) v.push_back(M(i, j));
  return v;
}

void expect_array(const json& section, const std::string& name, Eigen::Index tuples,
                  const std::vector<double>& values) {
  SCOPED_TRACE(name);
  ASSERT_TRUE(section.contains(name)) << section.dump().substr(0, 300);
  const json& a = section[name];
  EXPECT_EQ(a["tuples"].get<Eigen::Index>(), tuples);
  EXPECT_EQ(a["components"].get<std::size_t>() * std::size_t(tuples), values.size());
  EXPECT_EQ(a["values"].get<std::vector<double>>(), values);
}

}  // namespace

TEST(IoVtuVtk, VtkReadsEveryArrayWeWriteValueForValue) {
  if (!has_vtk()) GTEST_SKIP() << "/usr/bin/python3 with VTK (python3-vtk9) not available";
  const Fixture f = fixture();
  const TetMesh& m = f.mesh;
  std::vector<double> frame(m.frame.origin_mm.data(), m.frame.origin_mm.data() + 3);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 3; ++i) frame.push_back(m.frame.axes(i, c));
  const std::vector<double> source(m.source.begin(), m.source.end());
  for (VtuEncoding enc : {VtuEncoding::ascii, VtuEncoding::binary, VtuEncoding::zlib}) {
    SCOPED_TRACE(int(enc));
    const std::string dir = test::fresh_tmp_dir("io_vtu_vtk_", "ours_" + std::to_string(int(enc)));
    write_vtu(dir + "/ours.vtu", m, f.point, f.cell, {enc});
    const json got = json::parse(test::run_python(dir, kVtkDump, dir + "/ours.vtu"));
    // The field data VTK sized as empty before the arrays stated NumberOfTuples.
    expect_array(got["field"], "disc_frame", 1, frame);
    expect_array(got["field"], "source", Eigen::Index(source.size()), source);
    expect_array(got["point"], "surface", m.num_vertices(),
                 std::vector<double>(m.surface.data(), m.surface.data() + m.surface.size()));
    expect_array(got["cell"], "region", m.num_tets(),
                 std::vector<double>(m.region.data(), m.region.data() + m.region.size()));
    for (const DataArray& a : f.point) expect_array(got["point"], a.name, m.num_vertices(), flat(a.values));
    for (const DataArray& a : f.cell) expect_array(got["cell"], a.name, m.num_tets(), flat(a.values));
    EXPECT_EQ(got["field"].size(), 2u);
    EXPECT_EQ(got["point"].size(), 1 + f.point.size());
    EXPECT_EQ(got["cell"].size(), 1 + f.cell.size());
    EXPECT_EQ(got["points"].get<std::vector<double>>(), flat(m.V));
    const std::vector<double> connectivity = flat(m.T.cast<double>());
    EXPECT_EQ(got["connectivity"].get<std::vector<double>>(), connectivity);
    EXPECT_EQ(got["types"].get<std::vector<int>>(), std::vector<int>(std::size_t(m.num_tets()), 10));
  }
}

TEST(IoVtuVtk, VtkReadsTheSurfacesWeWrite) {
  if (!has_vtk()) GTEST_SKIP() << "/usr/bin/python3 with VTK (python3-vtk9) not available";
  TriSurface s;
  s.V = test::kuhn_cube_mesh().V;
  s.F.resize(2, 3);
  s.F << 0, 1, 3, 0, 3, 2;
  const Eigen::MatrixXd body = (Eigen::MatrixXd(2, 1) << 4, 17).finished();
  const std::string dir = test::fresh_tmp_dir("io_vtu_vtk_", "surface");
  write_surface_vtu(dir + "/s.vtu", s, {}, {{"body", body}}, {VtuEncoding::zlib});
  const json got = json::parse(test::run_python(dir, kVtkDump, dir + "/s.vtu"));
  expect_array(got["cell"], "body", 2, {4, 17});
  EXPECT_EQ(got["types"].get<std::vector<int>>(), std::vector<int>({5, 5}));
  EXPECT_EQ(got["points"].get<std::vector<double>>(), flat(s.V));
}

/// VTK reads our file and writes it back in every encoding it has; prints the file names.
const char* kVtkWritesEveryEncoding = R"PY(
import sys, vtk
src, d = sys.argv[1], sys.argv[2]
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(src)
r.Update()
names = []
def write(name, mode, compressor, header, encode=True):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(r.GetOutput())
    w.SetFileName(d + "/" + name)
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary, "appended": w.SetDataModeToAppended}[mode]()
    w.SetEncodeAppendedData(encode)
    {"none": w.SetCompressorTypeToNone, "zlib": w.SetCompressorTypeToZLib,
     "lz4": w.SetCompressorTypeToLZ4, "lzma": w.SetCompressorTypeToLZMA}[compressor]()
    {"UInt32": w.SetHeaderTypeToUInt32, "UInt64": w.SetHeaderTypeToUInt64}[header]()
    w.SetBlockSize(64)  # several blocks per array, a partial last one
    if w.Write() != 1:
        sys.exit("VTK could not write " + name)
    names.append(name)
for header in ("UInt32", "UInt64"):
    write("ascii-%s.vtu" % header, "ascii", "none", header)
    for compressor in ("none", "zlib", "lz4", "lzma"):
        write("binary-%s-%s.vtu" % (compressor, header), "binary", compressor, header)
        write("appended-raw-%s-%s.vtu" % (compressor, header), "appended", compressor, header, False)
        write("appended-base64-%s-%s.vtu" % (compressor, header), "appended", compressor, header, True)
print("\n".join(names))
)PY";

TEST(IoVtuVtk, ReadsEveryEncodingVtkWritesBackToTheSameMesh) {
  if (!has_vtk()) GTEST_SKIP() << "/usr/bin/python3 with VTK (python3-vtk9) not available";
  const Fixture f = fixture();
  const TetMesh& m = f.mesh;
  const std::string dir = test::fresh_tmp_dir("io_vtu_vtk_", "every_encoding");
  write_vtu(dir + "/source.vtu", m, f.point, f.cell, {VtuEncoding::binary});
  std::istringstream names(
      test::run_python(dir, kVtkWritesEveryEncoding, dir + "/source.vtu " + dir));
  int files = 0;
  for (std::string name; std::getline(names, name);) {
    SCOPED_TRACE(name);
    ++files;
    std::vector<DataArray> pd, cd;
    const TetMesh r = read_vtu(dir + "/" + name, &pd, &cd);
    // Exact in every encoding, ASCII too: VTK prints doubles in their shortest round-trip form.
    EXPECT_EQ(r.V, m.V);
    EXPECT_EQ(r.T, m.T);
    EXPECT_EQ(r.region, m.region);
    EXPECT_EQ(r.surface, m.surface);
    EXPECT_EQ(r.frame.origin_mm, m.frame.origin_mm);
    EXPECT_EQ(r.frame.axes, m.frame.axes);
    EXPECT_EQ(r.source, m.source);
    ASSERT_EQ(pd.size(), f.point.size());
    ASSERT_EQ(cd.size(), f.cell.size());
    for (std::size_t k = 0; k < pd.size(); ++k) {
      EXPECT_EQ(pd[k].name, f.point[k].name);
      EXPECT_EQ(pd[k].values, f.point[k].values) << pd[k].name;
    }
    for (std::size_t k = 0; k < cd.size(); ++k) {
      EXPECT_EQ(cd[k].name, f.cell[k].name);
      EXPECT_EQ(cd[k].values, f.cell[k].values) << cd[k].name;
    }
  }
  EXPECT_EQ(files, 2 * (1 + 4 * 3));  // 2 headers x (ASCII + 4 compressors x 3 layouts)
}

TEST(IoVtuVtk, AFrameVtkDroppedFromAnOlderFileIsNamedNotMisread) {
  if (!has_vtk()) GTEST_SKIP() << "/usr/bin/python3 with VTK (python3-vtk9) not available";
  // Field arrays without NumberOfTuples, as spinesim wrote them before: VTK reads them empty
  // and writes them back empty.
  const Fixture f = fixture();
  const std::string dir = test::fresh_tmp_dir("io_vtu_vtk_", "old_frame");
  write_vtu(dir + "/old.vtu", f.mesh, {}, {}, {VtuEncoding::ascii});
  std::string text = test::slurp(dir + "/old.vtu");
  for (std::size_t at; (at = text.find(" NumberOfTuples=\"")) != std::string::npos;)
    text.erase(at, text.find('"', at + 17) + 1 - at);
  test::spit(dir + "/old.vtu", text);
  const char* resave = R"PY(
import sys, vtk
r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update()
w = vtk.vtkXMLUnstructuredGridWriter(); w.SetInputData(r.GetOutput()); w.SetFileName(sys.argv[2]); w.Write()
print(r.GetOutput().GetFieldData().GetAbstractArray("disc_frame").GetNumberOfTuples())
)PY";
  EXPECT_EQ(test::run_python(dir, resave, dir + "/old.vtu " + dir + "/resaved.vtu"), "0\n");
  test::expect_one_line_refusal([&] { read_vtu(dir + "/resaved.vtu"); }, dir + "/resaved.vtu",
                                "'disc_frame' is empty");
}
