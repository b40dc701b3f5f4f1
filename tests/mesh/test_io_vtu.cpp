// VTU writer/reader: exact round trips, an independent reader (meshio) in both directions, and
// every kind of bad input giving a one-line std::invalid_argument with no file left behind.
#include "spinesim/mesh/io.hpp"

#include "io_fixtures.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace spinesim::mesh;

namespace {

/// The shared cube with a non-trivial frame and a source string that needs XML escaping.
TetMesh cube_mesh() {
  TetMesh m = test::kuhn_cube_mesh();
  m.frame.origin_mm << 1.5, -2.25, 1e-7;
  m.frame.axes << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // a 90° turn about z
  m.source = "unit test cube <&>";
  return m;
}

/// Hand-made fixtures next to this file.
std::string data_file(const std::string& name) {
  return (fs::path(__FILE__).parent_path() / "data" / name).string();
}

std::string tmp_dir(const std::string& name) { return test::fresh_tmp_dir("io_vtu_", name); }

using test::python_has;
using test::run_python;
using test::slurp;
using test::spit;

bool has_meshio() { return python_has("meshio, numpy"); }

int count_tmp_files(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) ++n;
  return n;
}

std::vector<DataArray> point_arrays(const TetMesh& m) {
  Eigen::MatrixXd disp(m.num_vertices(), 3), temp(m.num_vertices(), 1);
  for (Eigen::Index i = 0; i < m.num_vertices(); ++i) {
    disp.row(i) << 0.1 * i + 1e-17, -std::sqrt(double(i + 2)), std::ldexp(1.0, -int(i) - 40);
    temp(i) = std::exp(double(i)) / 7.0;
  }
  return {{"displacement", disp}, {"temperature", temp}};
}

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  ASSERT_EQ(a.V.rows(), b.V.rows());
  EXPECT_TRUE((a.V.array() == b.V.array()).all()) << "coordinates not bit-exact";
  EXPECT_EQ(a.T, b.T);
  EXPECT_EQ(a.region, b.region);
  EXPECT_EQ(a.surface, b.surface);
  EXPECT_TRUE((a.frame.origin_mm.array() == b.frame.origin_mm.array()).all());
  EXPECT_TRUE((a.frame.axes.array() == b.frame.axes.array()).all());
  EXPECT_EQ(a.source, b.source);
}

void round_trip(VtuEncoding enc, const std::string& name) {
  const std::string dir = tmp_dir(name);
  const std::string path = dir + "/cube.vtu";
  const TetMesh m = cube_mesh();
  const auto pd = point_arrays(m);
  Eigen::MatrixXd quality(m.num_tets(), 1);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) quality(t) = tet_volume(m, t);
  write_vtu(path, m, pd, {{"volume", quality}}, {enc});

  std::vector<DataArray> pd2, cd2;
  const TetMesh r = read_vtu(path, &pd2, &cd2);
  expect_same_mesh(m, r);
  ASSERT_EQ(pd2.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(pd2[k].name, pd[k].name);
    ASSERT_EQ(pd2[k].values.rows(), pd[k].values.rows());
    ASSERT_EQ(pd2[k].values.cols(), pd[k].values.cols());
    EXPECT_TRUE((pd2[k].values.array() == pd[k].values.array()).all());
  }
  ASSERT_EQ(cd2.size(), 1u);
  EXPECT_EQ(cd2[0].name, "volume");
  EXPECT_TRUE((cd2[0].values.array() == quality.array()).all());
  EXPECT_EQ(count_tmp_files(dir), 0);
}

}  // namespace

TEST(IoVtu, RoundTripBinaryIsBitExact) { round_trip(VtuEncoding::binary, "rt_binary"); }
TEST(IoVtu, RoundTripAsciiIsExact) { round_trip(VtuEncoding::ascii, "rt_ascii"); }
TEST(IoVtu, RoundTripZlibIsBitExact) { round_trip(VtuEncoding::zlib, "rt_zlib"); }

// Several 32 KiB blocks (a partial last one) and a compressor declared on the file.
TEST(IoVtu, ZlibSplitsLargeArraysIntoBlocksAndShrinksThem) {
  const std::string dir = tmp_dir("zlib_blocks");
  const TetMesh m = cube_mesh();
  Eigen::MatrixXd big(m.num_tets(), 5000);  // 5000 doubles a row: 40 kB, more than a block
  for (Eigen::Index i = 0; i < big.size(); ++i) big.data()[i] = double(i % 97);
  write_vtu(dir + "/z.vtu", m, {}, {{"big", big}}, {VtuEncoding::zlib});
  write_vtu(dir + "/b.vtu", m, {}, {{"big", big}}, {VtuEncoding::binary});
  EXPECT_NE(slurp(dir + "/z.vtu").find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_LT(fs::file_size(dir + "/z.vtu"), fs::file_size(dir + "/b.vtu") / 5);
  std::vector<DataArray> cd;
  read_vtu(dir + "/z.vtu", nullptr, &cd);
  ASSERT_EQ(cd.size(), 1u);
  EXPECT_TRUE((cd[0].values.array() == big.array()).all());
}

TEST(IoVtu, BinaryIsTheDefaultAndDeclaresItsLayout) {
  const std::string path = tmp_dir("layout") + "/cube.vtu";
  write_vtu(path, cube_mesh());
  const std::string text = slurp(path);
  EXPECT_NE(text.find("type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(text.find("byte_order=\"LittleEndian\""), std::string::npos);
  EXPECT_NE(text.find("header_type=\"UInt64\""), std::string::npos);
  EXPECT_NE(text.find("format=\"binary\""), std::string::npos);
  EXPECT_EQ(text.find("compressor"), std::string::npos);
}

TEST(IoVtu, OverwritesAnExistingFileAtomically) {
  const std::string dir = tmp_dir("overwrite");
  const std::string path = dir + "/cube.vtu";
  spit(path, "old content");
  write_vtu(path, cube_mesh());
  EXPECT_NO_THROW(read_vtu(path));
  EXPECT_EQ(count_tmp_files(dir), 0);
}

TEST(IoVtu, QuadraticTetKeepsCornersAndDropsMidpoints) {
  // Hand-made fixture: one VTK_QUADRATIC_TETRA (10 nodes), midpoint nodes carry surface 9.
  std::vector<DataArray> pd;
  const TetMesh m = read_vtu(data_file("quadratic_tet.vtu"), &pd);
  ASSERT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_tets(), 1);
  EXPECT_NEAR(tet_volume(m, 0), 1.0 / 6.0, 1e-15);
  EXPECT_EQ(m.surface.maxCoeff(), 2);  // midpoints (label 9) dropped
  ASSERT_EQ(pd.size(), 1u);
  EXPECT_EQ(pd[0].values.rows(), 4);
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_EQ(pd[0].values(i, 0), m.V(i, 0) + 10.0);
}

TEST(IoVtu, ReadsVtkStyleSeparatelyEncodedBinaryHeaders) {
  // Hand-made fixture: UInt32 headers base64-encoded apart from the data (VTK's own style),
  // Float32 points, Int32 connectivity, no region/surface arrays.
  const TetMesh m = read_vtu(data_file("tet_vtk_style_binary.vtu"));
  ASSERT_EQ(m.num_vertices(), 4);
  ASSERT_EQ(m.num_tets(), 1);
  EXPECT_EQ(m.region(0), 1);                       // missing region -> 1
  EXPECT_EQ(m.surface, Eigen::VectorXi::Zero(4));  // missing surface -> 0
  EXPECT_EQ(m.V(1, 0), 2.0);
  EXPECT_EQ(m.V(3, 2), 2.0);
  EXPECT_NEAR(tet_volume(m, 0), 8.0 / 6.0, 1e-12);
}

// --- independent reader: meshio -----------------------------------------------------------

namespace {
const char* kMeshioSummary = R"PY(
import sys, meshio, numpy as np
m = meshio.read(sys.argv[1])
tets = sum(len(c.data) for c in m.cells if c.type == "tetra")
print(len(m.points), tets)
print("%.17g" % np.sum(m.points * np.array([1.0, 2.0, 3.0])))
print(int(np.sum(np.concatenate(m.cell_data["region"]))), int(np.sum(m.point_data["surface"])))
print("%.17g" % np.sum(m.point_data["displacement"]))
print(" ".join("%.17g" % x for x in np.ravel(m.field_data["disc_frame"])))
)PY";
}

TEST(IoVtu, MeshioReadsWhatWeWrite) {
  if (!has_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  const TetMesh m = cube_mesh();
  const auto pd = point_arrays(m);
  for (VtuEncoding enc : {VtuEncoding::binary, VtuEncoding::ascii, VtuEncoding::zlib}) {
    const std::string dir = tmp_dir(enc == VtuEncoding::binary  ? "meshio_bin"
                                    : enc == VtuEncoding::ascii ? "meshio_ascii"
                                                                : "meshio_zlib");
    const std::string path = dir + "/cube.vtu";
    write_vtu(path, m, pd, {}, {enc});
    std::istringstream out(run_python(dir, kMeshioSummary, path));
    long np = -1, nt = -1, region_sum = -1, surface_sum = -1;
    double weighted = 0, disp_sum = 0;
    out >> np >> nt >> weighted >> region_sum >> surface_sum >> disp_sum;
    ASSERT_FALSE(out.fail()) << out.str();
    EXPECT_EQ(np, m.num_vertices());
    EXPECT_EQ(nt, m.num_tets());
    const double expected = m.V.col(0).sum() + 2 * m.V.col(1).sum() + 3 * m.V.col(2).sum();
    EXPECT_NEAR(weighted, expected, 1e-12 * std::abs(expected));
    EXPECT_EQ(region_sum, m.region.sum());
    EXPECT_EQ(surface_sum, m.surface.sum());
    EXPECT_NEAR(disp_sum, pd[0].values.sum(), 1e-12 * pd[0].values.cwiseAbs().sum());
    for (int k = 0; k < 12; ++k) {
      double f;
      out >> f;
      const double want = k < 3 ? m.frame.origin_mm(k) : m.frame.axes((k - 3) % 3, (k - 3) / 3);
      EXPECT_EQ(f, want) << "disc_frame[" << k << "]";
    }
  }
}

/// The four faces of a tetrahedron, outward.
TriSurface tetrahedron_surface() {
  TriSurface s;
  s.V.resize(4, 3);
  s.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1.5;
  s.F.resize(4, 3);
  s.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  return s;
}

// A triangle surface (vertebrae in a time series): meshio reads its triangles, points and cell
// array, in both binary encodings.
TEST(IoVtu, MeshioReadsATriangleSurface) {
  if (!has_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  const TriSurface s = tetrahedron_surface();
  const Eigen::MatrixXd body = Eigen::Vector4d(0, 1, 2, 3);
  for (VtuEncoding enc : {VtuEncoding::binary, VtuEncoding::zlib}) {
    const std::string dir = tmp_dir(enc == VtuEncoding::zlib ? "surf_zlib" : "surf_bin");
    write_surface_vtu(dir + "/s.vtu", s, {{"height", s.V.col(2)}}, {{"body", body}}, {enc});
    const std::string out = run_python(dir,
                                       "import sys, meshio\n"
                                       "m = meshio.read(sys.argv[1])\n"
                                       "t = m.cells_dict['triangle']\n"
                                       "print(len(m.points), len(t), int(t.sum()), "
                                       "m.points[:, 2].sum(), m.point_data['height'].sum(), "
                                       "m.cell_data['body'][0].sum())\n",
                                       dir + "/s.vtu");
    EXPECT_EQ(out, "4 4 18 1.5 1.5 6.0\n");
  }
  const std::string bad = tmp_dir("surf_bad") + "/s.vtu";
  EXPECT_THROW(write_surface_vtu(bad, s, {}, {{"body", Eigen::MatrixXd::Zero(3, 1)}}),
               std::invalid_argument);  // 3 values for 4 triangles
  TriSurface out_of_range = s;
  out_of_range.F(2, 1) = 4;
  EXPECT_THROW(write_surface_vtu(bad, out_of_range), std::invalid_argument);
  EXPECT_FALSE(fs::exists(bad));
}

// The playback reader: a surface and a tet mesh come back exactly as written (points, cells,
// arrays) in every encoding the writers have, an inverted tet included (a deformed frame);
// mixed cell kinds are refused in one line.
TEST(IoVtu, GridReaderReturnsWhatTheWritersWrote) {
  const TriSurface s = tetrahedron_surface();
  const Eigen::MatrixXd body = Eigen::Vector4d(0, 1, 2, 3);
  TetMesh m;
  m.V = s.V;
  m.T.resize(1, 4);
  m.T << 0, 2, 1, 3;  // inverted: read_vtu would refuse it, the grid reader keeps it
  m.surface = Eigen::VectorXi::Zero(4);
  m.region = Eigen::VectorXi::Ones(1);
  const Eigen::MatrixXd u = Eigen::MatrixXd::Constant(4, 3, 0.25);
  for (VtuEncoding enc : {VtuEncoding::binary, VtuEncoding::ascii, VtuEncoding::zlib}) {
    const std::string dir = tmp_dir("grid_" + std::to_string(int(enc)));
    write_surface_vtu(dir + "/s.vtu", s, {}, {{"body", body}}, {enc});
    const VtuGrid g = read_vtu_grid(dir + "/s.vtu");
    EXPECT_EQ(g.cell_type, 5);
    EXPECT_EQ(g.V, s.V);
    EXPECT_EQ(g.cells, Eigen::MatrixXi(s.F));
    ASSERT_NE(g.cell_array("body"), nullptr);
    EXPECT_EQ(g.cell_array("body")->values, body);
    EXPECT_EQ(g.point_array("body"), nullptr);
    write_vtu(dir + "/t.vtu", m, {{"displacement", u}}, {}, {enc});
    const VtuGrid t = read_vtu_grid(dir + "/t.vtu");
    EXPECT_EQ(t.cell_type, 10);
    EXPECT_EQ(t.cells, Eigen::MatrixXi(m.T));
    ASSERT_NE(t.point_array("displacement"), nullptr);
    EXPECT_EQ(t.point_array("displacement")->values, u);
    ASSERT_NE(t.cell_array("region"), nullptr);  // kept as an ordinary array
    EXPECT_THROW(read_vtu(dir + "/t.vtu"), std::invalid_argument);
  }
  const std::string dir = tmp_dir("grid_mixed");
  std::ofstream(dir + "/mixed.vtu")
      << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\"><UnstructuredGrid>"
         "<Piece NumberOfPoints=\"4\" NumberOfCells=\"2\"><Points><DataArray type=\"Float64\" "
         "NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>"
         "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 0 1 2 3"
         "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">3 7</DataArray>"
         "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">5 10</DataArray></Cells>"
         "</Piece></UnstructuredGrid></VTKFile>";
  test::expect_one_line_refusal([&] { read_vtu_grid(dir + "/mixed.vtu"); }, "mixed.vtu",
                                "one kind of cell");
  test::expect_one_line_refusal([&] { read_vtu_grid(dir + "/absent.vtu"); }, "absent.vtu",
                                "no such file");
}

// Every encoding of a tetrahedral mesh that python3-meshio writes — VTU ascii; binary with
// compression none/zlib/lzma and 32/64-bit headers; legacy VTK 4.2 and 5.1, ascii and binary —
// plus the appended encodings meshio does not write (ParaView's default), made by a small numpy
// writer in the script (raw and base64, uncompressed and zlib in several blocks, both header
// sizes): each must read back as the mesh we wrote, with the same points, cells and arrays.
const char* kEveryEncoding = R"PY(
import sys, base64, zlib, meshio, numpy as np
src, d = sys.argv[1], sys.argv[2]
m = meshio.read(src)
names = []
def out(name):
    names.append(name)
    return d + "/" + name
meshio.write(out("ascii.vtu"), m, binary=False)
for comp in (None, "zlib", "lzma"):
    for ht in ("UInt32", "UInt64"):
        meshio.write(out("binary-%s-%s.vtu" % (comp or "none", ht)), m, binary=True, compression=comp, header_type=ht)
for ver in ("4.2", "5.1"):
    for binary in (False, True):
        meshio.vtk.write(out("legacy-%s-%s.vtk" % (ver, "binary" if binary else "ascii")), m, fmt_version=ver, binary=binary)

def appended(path, encoding, compress, ht):
    hdt = {"UInt32": "<u4", "UInt64": "<u8"}[ht]
    tets = m.cells[0].data.astype("<i8")
    arrays = {  # section -> [(name, values, vtk type, components)]
        "Points": [("Points", m.points.astype("<f8"), "Float64", 3)],
        "Cells": [("connectivity", tets.ravel(), "Int64", 1),
                  ("offsets", np.arange(4, 4 * len(tets) + 1, 4, dtype="<i8"), "Int64", 1),
                  ("types", np.full(len(tets), 10, dtype="u1"), "UInt8", 1)],
        "PointData": [(k, v.astype("<i4" if v.dtype.kind == "i" else "<f8"), "Int32" if v.dtype.kind == "i" else "Float64",
                       1 if v.ndim == 1 else v.shape[1]) for k, v in m.point_data.items()],
        "CellData": [(k, v[0].astype("<i4" if v[0].dtype.kind == "i" else "<f8"), "Int32" if v[0].dtype.kind == "i" else "Float64",
                      1 if v[0].ndim == 1 else v[0].shape[1]) for k, v in m.cell_data.items()],
    }
    stream, xml = b"", {}
    for section, items in arrays.items():
        xml[section] = ""
        for name, values, vtk, ncomp in items:
            raw = np.ascontiguousarray(values).tobytes()
            if compress:
                bs = 48  # small blocks: several per array, a partial last one
                blocks = [raw[i:i + bs] for i in range(0, len(raw), bs)]
                comp = [zlib.compress(b) for b in blocks]
                last = len(blocks[-1]) if len(blocks[-1]) != bs else 0
                header = np.array([len(blocks), bs, last] + [len(c) for c in comp], dtype=hdt).tobytes()
                data = b"".join(comp)
            else:
                header, data = np.array([len(raw)], dtype=hdt).tobytes(), raw
            chunk = (base64.b64encode(header) + base64.b64encode(data)) if encoding == "base64" else header + data
            xml[section] += '<DataArray type="%s" Name="%s" NumberOfComponents="%d" format="appended" offset="%d"/>\n' % (vtk, name, ncomp, len(stream))
            stream += chunk
    text = ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="%s"%s>\n'
            '<UnstructuredGrid><Piece NumberOfPoints="%d" NumberOfCells="%d">\n<Points>%s</Points><Cells>%s</Cells>'
            '<PointData>%s</PointData><CellData>%s</CellData></Piece></UnstructuredGrid>\n<AppendedData encoding="%s">\n   _'
            % (ht, ' compressor="vtkZLibDataCompressor"' if compress else "", len(m.points), len(tets), xml["Points"],
               xml["Cells"], xml["PointData"], xml["CellData"], encoding)).encode()
    with open(out(path), "wb") as f:
        f.write(text + stream + b"\n</AppendedData>\n</VTKFile>\n")
for enc in ("raw", "base64"):
    for compress in (False, True):
        for ht in ("UInt32", "UInt64"):
            appended("appended-%s-%s-%s.vtu" % (enc, "zlib" if compress else "none", ht), enc, compress, ht)
print("\n".join(names))
)PY";

TEST(IoVtu, ReadsEveryEncodingMeshioWritesAndAppendedData) {
  if (!has_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  const std::string dir = tmp_dir("every_encoding");
  const TetMesh m = cube_mesh();
  const auto pd = point_arrays(m);
  Eigen::MatrixXd volume(m.num_tets(), 1);
  for (Eigen::Index t = 0; t < m.num_tets(); ++t) volume(t) = tet_volume(m, t);
  write_vtu(dir + "/source.vtu", m, pd, {{"volume", volume}});
  std::istringstream names(run_python(dir, kEveryEncoding, dir + "/source.vtu " + dir));
  int files = 0;
  for (std::string name; std::getline(names, name);) {
    SCOPED_TRACE(name);
    ++files;
    std::vector<DataArray> pd2, cd2;
    const TetMesh r = read_tet_mesh(dir + "/" + name, &pd2, &cd2);
    // Binary encodings are bit-exact; meshio's ASCII writers print fewer digits.
    const bool ascii = name.find("ascii") != std::string::npos;
    const double tol = ascii ? 1e-10 : 0.0;
    ASSERT_EQ(r.num_vertices(), m.num_vertices());
    EXPECT_LE((r.V - m.V).cwiseAbs().maxCoeff(), tol * m.V.cwiseAbs().maxCoeff());
    EXPECT_EQ(r.T, m.T);
    EXPECT_EQ(r.region, m.region);
    EXPECT_EQ(r.surface, m.surface);
    ASSERT_EQ(pd2.size(), pd.size());
    for (const DataArray& want : pd) {
      const auto got = std::find_if(pd2.begin(), pd2.end(),
                                    [&](const DataArray& a) { return a.name == want.name; });
      ASSERT_NE(got, pd2.end()) << want.name;
      ASSERT_EQ(got->values.rows(), want.values.rows()) << want.name;
      ASSERT_EQ(got->values.cols(), want.values.cols()) << want.name;
      EXPECT_LE((got->values - want.values).cwiseAbs().maxCoeff(),
                tol * want.values.cwiseAbs().maxCoeff() + (ascii ? 1e-300 : 0))
          << want.name;
    }
    ASSERT_EQ(cd2.size(), 1u);
    EXPECT_EQ(cd2[0].name, "volume");
    EXPECT_LE((cd2[0].values - volume).cwiseAbs().maxCoeff(), tol * volume.cwiseAbs().maxCoeff());
  }
  EXPECT_EQ(
      files,
      1 + 6 + 4 + 8);  // VTU ascii, binary x 3 compressions x 2 headers, legacy x 4, appended x 8
}

TEST(IoVtu, ReadsQuadraticTetsFromMeshio) {
  if (!has_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  const std::string dir = tmp_dir("from_meshio");
  const char* script = R"PY(
import sys, meshio, numpy as np
d = sys.argv[1]
pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) * 0.1 + 1.0 / 3.0
q = np.vstack([pts, [(pts[i] + pts[j]) / 2 for i, j in [(0,1),(1,2),(0,2),(0,3),(1,3),(2,3)]]])
meshio.write(d + "/tet10.vtu", meshio.Mesh(q, [("tetra10", np.arange(10)[None, :])]), binary=True)
print("ok")
)PY";
  ASSERT_EQ(run_python(dir, script, dir), "ok\n");
  const TetMesh q = read_vtu(dir + "/tet10.vtu");
  EXPECT_EQ(q.num_vertices(), 4);
  EXPECT_NEAR(mesh_volume(q), 1e-3 / 6.0, 1e-15);
}

// --- bad input ------------------------------------------------------------------------------

namespace {

/// Writes an ASCII VTU of the cube, applies `edit` to the text, and expects read_vtu to throw a
/// one-line invalid_argument naming the file and containing `needle`.
void expect_read_error(const std::string& name, const std::function<void(std::string&)>& edit,
                       const std::string& needle, VtuEncoding enc = VtuEncoding::ascii) {
  SCOPED_TRACE(name);
  const std::string path = tmp_dir("bad_" + name) + "/bad.vtu";
  write_vtu(path, cube_mesh(), {}, {}, {enc});
  std::string text = slurp(path);
  edit(text);
  spit(path, text);
  test::expect_one_line_refusal([&] { read_vtu(path); }, path, needle);
}

void replace_once(std::string& s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  ASSERT_NE(pos, std::string::npos) << from;
  s.replace(pos, from.size(), to);
}

/// Text between the opening tag of the DataArray named `name` and its closing tag.
std::pair<std::size_t, std::size_t> array_body(const std::string& s, const std::string& name) {
  const auto a = s.find(">", s.find("Name=\"" + name + "\"")) + 1;
  const auto b = s.find("</DataArray>", a);
  return {a, b};
}

}  // namespace

TEST(IoVtu, MissingFile) {
  EXPECT_THROW(read_vtu(tmp_dir("missing") + "/nope.vtu"), std::invalid_argument);
}

TEST(IoVtu, BadFilesGiveOneLineErrors) {
  expect_read_error(
      "not_xml", [](std::string& s) { s = "solid cube\nthis is not xml"; }, "XML");
  expect_read_error(
      "polydata",
      [](std::string& s) { replace_once(s, "type=\"UnstructuredGrid\"", "type=\"PolyData\""); },
      "not an UnstructuredGrid");
  expect_read_error(
      "npoints",
      [](std::string& s) { replace_once(s, "NumberOfPoints=\"8\"", "NumberOfPoints=\"9\""); },
      "NumberOfPoints");
  expect_read_error(  // a count is an integer: "8.0e0" is not read as 8 (nor "7.5e2" as 7)
      "npoints_float",
      [](std::string& s) { replace_once(s, "NumberOfPoints=\"8\"", "NumberOfPoints=\"8.0e0\""); },
      "NumberOfPoints");
  expect_read_error(
      "index_range",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "connectivity");
        s.replace(a, b - a, "0 1 3 7 0 1 5 7 0 2 3 7 0 2 6 7 0 4 5 7 0 4 6 8");
      },
      "connectivity");
  expect_read_error(
      "nan_point",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "Points");
        const auto first = s.find_first_not_of(" \n", a);
        s.replace(first, s.find(' ', first) - first, "nan");
      },
      "non-finite");
  expect_read_error(  // a finite coordinate no mesh in mm has: named, not a "zero-volume" tet
      "huge_point",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "Points");
        const auto first = s.find_first_not_of(" \n", a);
        s.replace(first, s.find(' ', first) - first, "1e200");
      },
      "beyond 1e6 mm");
  expect_read_error(
      "garbage_number",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "Points");
        s.insert(a, " 1.0abc ");
      },
      "not a number");
  expect_read_error(
      "truncated_base64",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "Points");
        s.erase(a + (b - a) / 2, b - a - (b - a) / 2);
      },
      "truncated", VtuEncoding::binary);
  expect_read_error(
      "bad_base64_char",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "Points");
        s[a + 20] = '*';
      },
      "base64", VtuEncoding::binary);
}

// Encodings and compression that cannot be read, corrupt or hostile.
TEST(IoVtu, BadEncodingsGiveOneLineErrors) {
  expect_read_error(
      "appended",
      [](std::string& s) {
        replace_once(s, "format=\"ascii\">", "format=\"appended\" offset=\"0\">");
      },
      "appended");
  expect_read_error(
      "unknown_compressor",
      [](std::string& s) {
        replace_once(s, "header_type=", "compressor=\"vtkBrotliDataCompressor\" header_type=");
      },
      "vtkBrotliDataCompressor");
  expect_read_error(
      "corrupt_lz4",
      [](std::string& s) {
        // An LZ4 block whose literal run claims more bytes than the block holds.
        replace_once(s, "header_type=\"UInt64\"",
                     "header_type=\"UInt32\" compressor=\"vtkLZ4DataCompressor\"");
        const auto [a, b] = array_body(s, "Points");
        s.replace(a, b - a, "AQAAAGAAAABgAAAACAAAAA==8P8BAgMEBQY=");
      },
      "does not decompress", VtuEncoding::binary);
  expect_read_error(
      "corrupt_zlib",
      [](std::string& s) {
        // A compressed file whose block does not inflate: a 1-block header, then garbage.
        replace_once(s, "header_type=\"UInt64\"",
                     "header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"");
        const auto [a, b] = array_body(s, "Points");
        s.replace(a, b - a, "AQAAAGAAAABgAAAACAAAAA==AAECAwQFBgc=");
      },
      "does not decompress", VtuEncoding::binary);
  expect_read_error(
      "huge_block",
      [](std::string& s) {
        // 2^32-1 blocks announced in 12 bytes of data.
        replace_once(s, "header_type=\"UInt64\"",
                     "header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"");
        const auto [a, b] = array_body(s, "Points");
        s.replace(a, b - a, "/////wAAAAAAAAAA");
      },
      "truncated", VtuEncoding::binary);
  expect_read_error(
      "hexahedron",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "types");
        s.replace(a, b - a, "10 10 10 10 10 12");
      },
      "hexahedron");
  expect_read_error(
      "offsets",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "offsets");
        s.replace(a, b - a, "4 8 12 16 20 23");
      },
      "offsets");
  expect_read_error(
      "region_size",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "region");
        s.replace(a, b - a, "1 2 1");
      },
      "region");
  expect_read_error(
      "inverted",
      [](std::string& s) {
        const auto [a, b] = array_body(s, "connectivity");
        const std::string body = s.substr(a, b - a);
        // swap the last two indices of the first tet
        std::istringstream is(body);
        std::vector<std::string> v{std::istream_iterator<std::string>(is), {}};
        std::swap(v[2], v[3]);
        std::string out;
        for (const auto& x : v) out += x + " ";
        s.replace(a, b - a, out);
      },
      "inverted");
}

TEST(IoVtu, RefusesNonFiniteDataAndLeavesNoFile) {
  const std::string dir = tmp_dir("nan_write");
  const std::string path = dir + "/out.vtu";
  TetMesh m = cube_mesh();
  auto pd = point_arrays(m);
  pd[0].values(3, 1) = std::numeric_limits<double>::quiet_NaN();
  for (VtuEncoding enc : {VtuEncoding::binary, VtuEncoding::ascii}) {
    try {
      write_vtu(path, m, pd, {}, {enc});
      FAIL() << "NaN accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("contains non-finite values"), std::string::npos)
          << e.what();
    }
  }
  m.V(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_vtu(path, m), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(count_tmp_files(dir), 0);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(IoVtu, RefusesBadArraysAndLabels) {
  const std::string dir = tmp_dir("bad_write");
  const std::string path = dir + "/out.vtu";
  const TetMesh m = cube_mesh();
  EXPECT_THROW(write_vtu(path, m, {{"short", Eigen::MatrixXd::Zero(3, 1)}}), std::invalid_argument);
  EXPECT_THROW(write_vtu(path, m, {{"surface", Eigen::MatrixXd::Zero(8, 1)}}),
               std::invalid_argument);
  EXPECT_THROW(write_vtu(path, m, {}, {{"region", Eigen::MatrixXd::Zero(6, 1)}}),
               std::invalid_argument);
  EXPECT_THROW(write_vtu(path, m, {{"", Eigen::MatrixXd::Zero(8, 1)}}), std::invalid_argument);
  TetMesh bad = m;
  bad.region.resize(2);
  EXPECT_THROW(write_vtu(path, bad), std::invalid_argument);
  bad = m;
  bad.T(0, 0) = 8;
  EXPECT_THROW(write_vtu(path, bad), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(IoVtu, MissingFolderIsARuntimeErrorAndLeavesNothing) {
  const std::string dir = tmp_dir("no_folder");
  EXPECT_THROW(write_vtu(dir + "/does/not/exist/out.vtu", cube_mesh()), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
}

// Found by fuzzing: a legacy VTK count so large that 3 x count overflowed (undefined behaviour
// before any check). Every count is now bounded by the file's size, so products of counts cannot
// overflow; a count with trailing characters is not a count.
TEST(IoVtu, LegacyCountsBeyondTheFileAreRefused) {
  const std::string dir = test::fresh_tmp_dir("io_vtu_", "legacy_counts");
  const std::string head =
      "# vtk DataFile Version 5.1\nwritten by a test\nBINARY\n"
      "DATASET UNSTRUCTURED_GRID\n";
  for (const auto& [name, points] : std::vector<std::pair<std::string, std::string>>{
           {"overflow", "3980433795905195575"}, {"beyond", "4000"}, {"suffix", "8abc"}}) {
    const std::string path = dir + "/" + name + ".vtk";
    std::ofstream(path, std::ios::binary) << head << "POINTS " << points << " double\n"
                                          << std::string(64, '\0');
    test::expect_one_line_refusal([&] { read_tet_mesh(path); }, path,
                                  name == "suffix" ? "is not a count" : "can hold");
  }
}

// A disc frame that is not a rotation would turn every load case into another load (zero axes:
// no load; axes x1000: a 1000-fold load; skewed axes: a sideways one): the reader refuses it.
TEST(IoVtu, ADiscFrameThatIsNotARotationIsRefused) {
  const std::string dir = tmp_dir("bad_frames");
  const std::vector<std::pair<std::string, Eigen::Matrix3d>> bad = {
      {"zero", Eigen::Matrix3d::Zero()},
      {"tiny", 1e-300 * Eigen::Matrix3d::Identity()},
      {"large", 1000 * Eigen::Matrix3d::Identity()},
      {"skewed", (Eigen::Matrix3d() << 1, 0.3, 0, 0, 1, 0, 0, 0, 1).finished()}};
  for (const auto& [name, axes] : bad) {
    SCOPED_TRACE(name);
    DiscFrame f;
    f.axes = axes;
    EXPECT_THROW(validate_frame(f), std::invalid_argument);
    // Written by hand (the writer is not the guard), read back through the reader.
    TetMesh m = cube_mesh();
    write_vtu(dir + "/ok.vtu", m, {}, {}, {VtuEncoding::ascii});
    std::string text;
    {
      std::ifstream in(dir + "/ok.vtu");
      text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const auto at = text.find("Name=\"disc_frame\"");
    ASSERT_NE(at, std::string::npos);
    const auto open = text.find('>', at) + 1, close = text.find("</DataArray>", open);
    std::ostringstream numbers;
    numbers.precision(17);
    numbers << "1.5 -2.25 1e-7";
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) numbers << ' ' << axes(i, c);
    text.replace(open, close - open, numbers.str());
    std::ofstream(dir + "/" + name + ".vtu") << text;
    try {
      read_tet_mesh(dir + "/" + name + ".vtu");
      ADD_FAILURE() << "read";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("disc_frame"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  DiscFrame rotated;
  rotated.axes = Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  EXPECT_NO_THROW(validate_frame(rotated));
  // A mirrored frame (a mirrored disc) keeps every load's magnitude: accepted.
  DiscFrame mirror;
  mirror.axes = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  EXPECT_NO_THROW(validate_frame(mirror));
}

// A mesh's fibre paths travel with it: written as `fibre_path_direction_1/2` after `region`, read
// back bit-exactly into TetMesh::fibre_paths (not into the caller's arrays), in every encoding;
// the names are reserved, and a file with one family, or a direction that is not a unit vector,
// is refused in one line.
TEST(IoVtu, FibrePathsTravelWithTheMesh) {
  const std::string dir = tmp_dir("fibre_paths");
  TetMesh m = cube_mesh();
  m.fibre_paths.direction_1.setZero(m.num_tets(), 3);
  m.fibre_paths.direction_2.setZero(m.num_tets(), 3);
  for (Eigen::Index t = 1; t < m.num_tets(); ++t) {  // tet 0 has none
    m.fibre_paths.direction_1.row(t) = Eigen::RowVector3d(1, 0.1 * t, -0.3).normalized();
    m.fibre_paths.direction_2.row(t) = Eigen::RowVector3d(-0.2, 1, 0.01 * t).normalized();
  }
  for (const VtuEncoding enc : {VtuEncoding::binary, VtuEncoding::ascii, VtuEncoding::zlib}) {
    const std::string path = dir + "/paths.vtu";
    Eigen::MatrixXd volume(m.num_tets(), 1);
    volume.setOnes();
    write_vtu(path, m, {}, {{"volume", volume}}, {enc});
    std::vector<DataArray> cells;
    const TetMesh r = read_vtu(path, nullptr, &cells);
    expect_same_mesh(m, r);
    EXPECT_TRUE((r.fibre_paths.direction_1.array() == m.fibre_paths.direction_1.array()).all());
    EXPECT_TRUE((r.fibre_paths.direction_2.array() == m.fibre_paths.direction_2.array()).all());
    ASSERT_EQ(cells.size(), 1u);
    EXPECT_EQ(cells[0].name, "volume");
  }
  // A mesh without paths reads back without them.
  write_vtu(dir + "/bare.vtu", cube_mesh());
  EXPECT_TRUE(read_vtu(dir + "/bare.vtu").fibre_paths.empty());
  // Reserved names, and paths that are not one unit row per tet, are refused before writing.
  const Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(m.num_tets(), 3);
  EXPECT_THROW(write_vtu(dir + "/x.vtu", cube_mesh(), {}, {{kFibrePathArray[0], rows}}),
               std::invalid_argument);
  TetMesh bad = m;
  bad.fibre_paths.direction_2.row(2) *= 1.01;
  test::expect_one_line_refusal([&] { write_vtu(dir + "/x.vtu", bad); }, dir + "/x.vtu",
                                "fibre_path_direction_2: tet #2 has a direction of length");
  bad = m;
  bad.fibre_paths.direction_1.conservativeResize(m.num_tets() - 1, 3);
  EXPECT_THROW(write_vtu(dir + "/x.vtu", bad), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir + "/x.vtu"));
  // Files: one family alone; a non-unit direction (both through the reader).
  write_vtu(dir + "/one.vtu", cube_mesh(), {}, {{"fibre_path_direction_9", rows}},
            {VtuEncoding::ascii});
  std::string text = slurp(dir + "/one.vtu");
  text.replace(text.find("fibre_path_direction_9"), 22, kFibrePathArray[0]);
  spit(dir + "/one.vtu", text);
  test::expect_one_line_refusal([&] { read_vtu(dir + "/one.vtu"); }, dir + "/one.vtu",
                                "without the other");
  write_vtu(dir + "/long.vtu", m, {}, {}, {VtuEncoding::ascii});
  text = slurp(dir + "/long.vtu");
  const auto at = text.find('>', text.find("Name=\"fibre_path_direction_1\"")) + 1;
  text.replace(text.find_first_not_of(" \n", at), 1, "7");  // tet 0's x: 0 -> 7
  spit(dir + "/long.vtu", text);
  test::expect_one_line_refusal([&] { read_vtu(dir + "/long.vtu"); }, dir + "/long.vtu",
                                "tet #0 has a direction of length 7");
}
