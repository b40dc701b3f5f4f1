// Surface import: every format on tiny files written here, units and the up-axis maps on known
// coordinates, the maps being proper rotations, bad input, and the real ArtiSynth L4 surfaces
// (skipped when the external test data are absent).
#include "spinesim/mesh/io.hpp"

#include "io_fixtures.hpp"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace spinesim::mesh;

namespace {

std::string tmp_dir(const std::string& name) { return test::fresh_tmp_dir("io_surface_", name); }

std::string spit(const std::string& path, const std::string& text) {
  std::ofstream os(path, std::ios::binary);
  os << text;
  return path;
}

/// Binary STL with the given triangles (each 9 floats).
std::string write_binary_stl(const std::string& path,
                             const std::vector<std::array<float, 9>>& tris) {
  std::ofstream os(path, std::ios::binary);
  char header[80] = "binary stl written by test_io_surface";
  os.write(header, 80);
  const std::uint32_t n = std::uint32_t(tris.size());
  os.write(reinterpret_cast<const char*>(&n), 4);
  for (const auto& t : tris) {
    const float normal[3] = {0, 0, 0};
    os.write(reinterpret_cast<const char*>(normal), 12);
    os.write(reinterpret_cast<const char*>(t.data()), 36);
    const std::uint16_t attr = 0;
    os.write(reinterpret_cast<const char*>(&attr), 2);
  }
  return path;
}

/// Row of V closest to p (exact match expected).
Eigen::Index find_vertex(const TriSurface& s, const Eigen::Vector3d& p) {
  Eigen::Index best = -1;
  (s.V.rowwise() - p.transpose()).rowwise().norm().minCoeff(&best);
  return best;
}

void expect_error(const std::string& path, double units, const std::string& needle) {
  SCOPED_TRACE(path);
  test::expect_one_line_refusal([&] { read_surface(path, units, UpAxis::y); }, path, needle);
}

}  // namespace

TEST(IoSurface, OffWithQuadUnitsAndZUp) {
  const std::string dir = tmp_dir("off");
  const std::string path = spit(dir + "/patch.off",
                                "OFF\n# a quad and a triangle\n5 2 0\n0 0 0\n1 0 0\n1 2 0\n0 2 0\n"
                                "0 0 3\n4 0 1 2 3\n3 0 1 4\n");
  const TriSurface s = read_surface(path, 10.0, UpAxis::z);
  ASSERT_EQ(s.V.rows(), 5);
  ASSERT_EQ(s.F.rows(), 3);  // quad fanned into 2 triangles
  // (x, y, z)_file × 10 -> (y, z, x)
  EXPECT_EQ(s.V.row(2), Eigen::RowVector3d(20, 0, 10));
  EXPECT_EQ(s.V.row(4), Eigen::RowVector3d(0, 30, 0));  // file z (up) -> +y
  EXPECT_EQ(s.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(s.F.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(s.F.row(2), Eigen::RowVector3i(0, 1, 4));
}

TEST(IoSurface, ObjWithNormalsTexturesGroupsAndNegativeIndices) {
  const std::string dir = tmp_dir("obj");
  const std::string path = spit(dir + "/patch.OBJ",  // upper-case extension on purpose
                                "# comment\nmtllib x.mtl\no patch\ng group\n"
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                "vn 0 0 1\nvn 0 0 1\nvt 0 0\nvt 1 0\nusemtl skin\ns off\n"
                                "f 1/1/1 2/2/2 3/2/2\nf 1//1 3//1 4//1\nf -4 -2 -1\n");
  const TriSurface s = read_surface(path, 1.0, UpAxis::y);
  ASSERT_EQ(s.V.rows(), 4);
  ASSERT_EQ(s.F.rows(), 3);
  EXPECT_EQ(s.F.row(0), Eigen::RowVector3i(0, 1, 2));
  EXPECT_EQ(s.F.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(s.F.row(2), Eigen::RowVector3i(0, 2, 3));  // relative indices
  EXPECT_EQ(s.V.row(2), Eigen::RowVector3d(1, 1, 0));  // identity for up = y
}

TEST(IoSurface, StlAsciiAndBinaryMergeVerticesAndMapXUp) {
  const std::string dir = tmp_dir("stl");
  const std::string ascii = spit(dir + "/a.stl",
                                 "solid t\n facet normal 0 0 1\n  outer loop\n"
                                 "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 2 0\n"
                                 "  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n"
                                 "   vertex 1 0 0\n   vertex 1 2 0\n   vertex 0 2 0\n"
                                 "  endloop\n endfacet\nendsolid t\n");
  const std::string binary =
      write_binary_stl(dir + "/b.stl", {{0, 0, 0, 1, 0, 0, 0, 2, 0}, {1, 0, 0, 1, 2, 0, 0, 2, 0}});
  for (const std::string& path : {ascii, binary}) {
    SCOPED_TRACE(path);
    const TriSurface s = read_surface(path, 1.0, UpAxis::x);
    ASSERT_EQ(s.V.rows(), 4);  // shared corners merged
    ASSERT_EQ(s.F.rows(), 2);
    // (x, y, z) -> (z, x, y): file (1, 2, 0) -> (0, 1, 2)
    EXPECT_GE(find_vertex(s, {0, 1, 2}), 0);
    EXPECT_EQ((s.V.row(find_vertex(s, {0, 1, 2})) - Eigen::RowVector3d(0, 1, 2)).norm(), 0.0);
  }
}

TEST(IoSurface, PlyAscii) {
  const std::string dir = tmp_dir("ply");
  const std::string path = spit(dir + "/t.ply",
                                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                "property float y\nproperty float z\nelement face 1\n"
                                "property list uchar int vertex_indices\nend_header\n"
                                "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  const TriSurface s = read_surface(path, 1000.0, UpAxis::minus_z);
  ASSERT_EQ(s.V.rows(), 4);
  ASSERT_EQ(s.F.rows(), 2);
  // minus_z: (x, y, z) -> (y, -z, -x); file (1, 1, 0) m -> (1000, 0, -1000) mm
  EXPECT_EQ(s.V.row(2), Eigen::RowVector3d(1000, 0, -1000));
}

// --- our OFF and PLY readers against CGAL's, on valid files of every flavour ------------------

namespace {

struct Soup {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<std::size_t>> polygons;
};

/// A closed test surface: a cube's 8 corners with 6 quads, plus a fan of 5 triangles over its top,
/// coordinates exactly representable as float (so every flavour stores them exactly).
Soup test_soup() {
  Soup s;
  for (int k = 0; k < 8; ++k)
    s.points.emplace_back(k & 1 ? 12.5 : -3.25, k & 2 ? 7.0 : -1.5, k & 4 ? 40.125 : 2.0);
  s.points.emplace_back(4.625, 2.75, 41.0);  // apex
  s.polygons = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5},
                {4, 5, 8},    {5, 7, 8},    {7, 6, 8},    {6, 4, 8},    {1, 3, 8}};
  return s;
}

std::string off_text(const Soup& s) {
  std::ostringstream os;
  os << "COFF 9 11 0  # colours per vertex, counts on the keyword line\n\n";
  for (const auto& p : s.points) os << p.x() << ' ' << p.y() << ' ' << p.z() << " 0.5 0.5 0.5 1\n";
  for (const auto& f : s.polygons) {
    os << f.size();
    for (auto i : f) os << ' ' << i;
    os << "  # a face\n";
  }
  return os.str();
}

template <class T>
void put(std::string& out, T v, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

/// PLY with an extra vertex property (a colour), an extra element before the faces and one list
/// per face; coordinates as float or double, indices as int or uint.
std::string ply_bytes(const Soup& s, const std::string& format, bool doubles) {
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  std::string out = "ply\r\nformat " + format + " 1.0\r\ncomment written by test_io_surface\r\n";
  const std::string coord = doubles ? "double" : "float";
  out += "element vertex 9\nproperty " + coord + " x\nproperty uchar red\nproperty " + coord +
         " y\nproperty " + coord + " z\n";
  out += "element note 2\nproperty list uchar short values\n";
  out += "element face 11\nproperty list uchar " + std::string(doubles ? "uint" : "int") +
         " vertex_indices\nproperty float quality\nend_header\n";
  std::ostringstream text;
  for (const auto& p : s.points) {
    if (ascii) {
      text << p.x() << " 200 " << p.y() << ' ' << p.z() << '\n';
    } else if (doubles) {
      put(out, p.x(), big), put(out, std::uint8_t(200), big), put(out, p.y(), big),
          put(out, p.z(), big);
    } else {
      put(out, float(p.x()), big), put(out, std::uint8_t(200), big), put(out, float(p.y()), big),
          put(out, float(p.z()), big);
    }
  }
  for (int note = 0; note < 2; ++note) {
    if (ascii)
      text << "3 -7 8 9\n";
    else
      put(out, std::uint8_t(3), big), put(out, std::int16_t(-7), big),
          put(out, std::int16_t(8), big), put(out, std::int16_t(9), big);
  }
  for (const auto& f : s.polygons) {
    if (ascii) {
      text << f.size();
      for (auto i : f) text << ' ' << i;
      text << " 0.5\n";
      continue;
    }
    put(out, std::uint8_t(f.size()), big);
    for (auto i : f) doubles ? put(out, std::uint32_t(i), big) : put(out, std::int32_t(i), big);
    put(out, 0.5f, big);
  }
  return out + text.str();
}

/// What CGAL's reader makes of the file.
Soup cgal_soup(const std::string& path) {
  std::vector<CGAL::Simple_cartesian<double>::Point_3> points;
  Soup s;
  EXPECT_TRUE(CGAL::IO::read_polygon_soup(path, points, s.polygons)) << path;
  for (const auto& p : points) s.points.emplace_back(p.x(), p.y(), p.z());
  return s;
}

/// Our reading of the file as a soup: read_surface's triangles, un-fanned against `expected`.
void expect_reads_as(const std::string& path, const Soup& expected) {
  SCOPED_TRACE(path);
  const Soup oracle = cgal_soup(path);
  ASSERT_EQ(oracle.points.size(), expected.points.size());
  EXPECT_EQ(oracle.polygons, expected.polygons);
  for (std::size_t i = 0; i < expected.points.size(); ++i)
    EXPECT_EQ(oracle.points[i], expected.points[i]) << i;
  const TriSurface ours = read_surface(path, 1.0, UpAxis::y);
  ASSERT_EQ(ours.V.rows(), Eigen::Index(expected.points.size()));
  for (std::size_t i = 0; i < expected.points.size(); ++i)
    EXPECT_EQ(ours.V.row(Eigen::Index(i)).transpose(), expected.points[i]) << i;
  Eigen::Index t = 0;
  for (const auto& f : expected.polygons)
    for (std::size_t k = 1; k + 1 < f.size(); ++k, ++t)
      EXPECT_EQ(ours.F.row(t), Eigen::RowVector3i(int(f[0]), int(f[k]), int(f[k + 1]))) << t;
  EXPECT_EQ(ours.F.rows(), t);
}

}  // namespace

TEST(IoSurface, OffAndPlyReadAsCgalReadsThemInEveryFlavour) {
  const std::string dir = tmp_dir("flavours");
  const Soup s = test_soup();
  expect_reads_as(spit(dir + "/cube.off", off_text(s)), s);
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"})
    for (const bool doubles : {false, true})
      expect_reads_as(spit(dir + "/cube-" + format + (doubles ? "-d" : "-f") + ".ply",
                           ply_bytes(s, format, doubles)),
                      s);
}

// Malformed OFF and PLY files, among them what fuzzing CGAL's readers found (a non-integer face
// index, a property before any element) and counts beyond the file: refused in one line, before
// any allocation the counts ask for.
TEST(IoSurface, MalformedOffAndPlyAreRefusedWithTheReason) {
  const std::string dir = tmp_dir("malformed");
  const std::string tri = "0 0 0\n1 0 0\n0 1 0\n";
  expect_error(spit(dir + "/frac.off", "OFF\n3 1 0\n" + tri + "3 0 1 -7.07\n"), 1,
               "is not a non-negative integer");
  expect_error(spit(dir + "/counts.off", "OFF\n3000000000 1 0\n" + tri + "3 0 1 2\n"), 1,
               "has only 4 lines for them");
  expect_error(spit(dir + "/short.off", "OFF\n3 2 0\n" + tri + "3 0 1 2\n"), 1, "has only 4 lines");
  expect_error(spit(dir + "/more.off", "OFF\n3 1 0\n" + tri + "3 0 1 2\n3 2 1 0\n"), 1,
               "1 more lines follow them");
  expect_error(spit(dir + "/binary.off", "OFF BINARY\n"), 1, "binary OFF");
  expect_error(spit(dir + "/4d.off", "4OFF\n3 1 0\n"), 1, "4D or nD");
  expect_error(spit(dir + "/nanv.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"), 1,
               "vertex #1 is not three finite numbers");
  const std::string head = "ply\nformat ascii 1.0\n";
  const std::string vertex =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  expect_error(
      spit(dir + "/early.ply", head + "property float x\n" + vertex + face + tri + "3 0 1 2\n"), 1,
      "property before any element");
  expect_error(spit(dir + "/count.ply",
                    head +
                        "element vertex 99999999999\nproperty float x\nproperty float y\n"
                        "property float z\n" +
                        face + tri + "3 0 1 2\n"),
               1, "more than the file holds");
  expect_error(spit(dir + "/list.ply", head + vertex + face + tri + "200 0 1 2\n"), 1,
               "length beyond the file");
  expect_error(spit(dir + "/ends.ply", head + vertex + face + tri + "3 0 1\n"), 1,
               "the PLY body ends early");
  expect_error(spit(dir + "/neg.ply", head + vertex + face + tri + "3 0 1 -1\n"), 1,
               "negative vertex index");
  // Found by fuzzing: an ASCII value beyond its integer type (1e85 as an int index).
  expect_error(spit(dir + "/huge.ply", head + vertex + face + tri + "3 0 1 1e85\n"), 1,
               "is not a finite integer");
  expect_error(spit(dir + "/range.ply", head + vertex + face + tri + "3 0 1 3\n"), 1,
               "out of range");
  expect_error(spit(dir + "/noend.ply", head + vertex), 1, "no end_header");
  expect_error(
      spit(dir + "/nox.ply", head + "element vertex 3\nproperty float y\nproperty float z\n" +
                                 face + tri + "3 0 1 2\n"),
      1, "no vertex element with x, y and z");
  std::string big = "ply\nformat binary_little_endian 1.0\n" + vertex +
                    "element face 1\nproperty list uint int vertex_indices\nend_header\n";
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(big, v, false);
  put(big, std::uint32_t(4000000000u), false);  // a list of 4e9 indices in a 60-byte body
  expect_error(spit(dir + "/hugelist.ply", big), 1, "length beyond the file");
}

TEST(IoSurface, EveryUpAxisMapIsARotationSendingUpToPlusY) {
  const std::string dir = tmp_dir("rotations");
  const std::string path = spit(dir + "/axes.off",
                                "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const struct {
    UpAxis up;
    Eigen::Vector3d up_file;
  } cases[] = {
      {UpAxis::x, {1, 0, 0}},        {UpAxis::y, {0, 1, 0}},        {UpAxis::z, {0, 0, 1}},
      {UpAxis::minus_x, {-1, 0, 0}}, {UpAxis::minus_y, {0, -1, 0}}, {UpAxis::minus_z, {0, 0, -1}},
  };
  for (const auto& c : cases) {
    const TriSurface s = read_surface(path, 1.0, c.up);
    Eigen::Matrix3d R;  // columns: images of the file's unit axes
    for (int k = 0; k < 3; ++k) R.col(k) = (s.V.row(k + 1) - s.V.row(0)).transpose();
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0, 1e-15);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
    EXPECT_NEAR((R * c.up_file - Eigen::Vector3d::UnitY()).norm(), 0, 1e-15);
  }
}

TEST(IoSurface, BadInputGivesOneLineErrors) {
  const std::string dir = tmp_dir("bad");
  expect_error(dir + "/missing.stl", 1, "no such file");
  expect_error(spit(dir + "/cloud.xyz", "0 0 0\n"), 1, "unknown surface file extension");
  expect_error(spit(dir + "/noext", "0 0 0\n"), 1, "unknown surface file extension");
  expect_error(spit(dir + "/empty.off", "OFF\n0 0 0\n"), 1, "no triangles");
  expect_error(spit(dir + "/empty.stl", ""), 1, "no triangles");
  expect_error(spit(dir + "/empty.obj", ""), 1, "cannot be read");
  expect_error(spit(dir + "/garbage.obj", "hello world\n"), 1, "cannot be read");
  expect_error(spit(dir + "/garbage.ply", "not a ply\n"), 1, "cannot be read");
  // CGAL's own check lets index == vertex count through; ours does not.
  expect_error(spit(dir + "/range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), 1, "out of range");
  expect_error(spit(dir + "/range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), 1,
               "out of range");
  expect_error(spit(dir + "/edge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), 1, "fewer than 3");
  // An index CGAL cannot read is dropped from the face: the message says what that means.
  expect_error(spit(dir + "/huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 1e20\n"), 1,
               "not an integer");
  // A binary STL whose facet count is a little off (a truncated or padded file): CGAL would read
  // as many facets as the count says and open a hole; refused by its size.
  const std::string stl = write_binary_stl(
      dir + "/count.stl", {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {1, 0, 0, 1, 1, 0, 0, 1, 0}});
  for (const std::uint32_t count : {1u, 3u}) {
    std::fstream f(stl, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(80);
    f.write(reinterpret_cast<const char*>(&count), 4);
    f.close();
    expect_error(stl, 1, "header counts " + std::to_string(count) + " facets");
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  expect_error(write_binary_stl(dir + "/nan.stl", {{0, 0, 0, 1, 0, 0, 0, nan, 0}}), 1,
               "non-finite");
  const std::string ok = spit(dir + "/ok.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NO_THROW(read_surface(ok, 1, UpAxis::y));
  expect_error(ok, 0, "unit scale");
  expect_error(ok, -1000, "unit scale");
  expect_error(ok, std::numeric_limits<double>::quiet_NaN(), "unit scale");
}

// --- real data: ArtiSynth lumbar surfaces (metres, z up, x anterior-posterior) ----------------

TEST(IoSurface, RealL4BodyBoundingBoxAndAnteriorDirection) {
  const fs::path root = fs::path(SPINESIM_TESTDATA_DIR) / "artisynth-lss";
  if (!fs::exists(root / "L4_body.obj") || !fs::exists(root / "L4_Schrumpfverpacken.obj"))
    GTEST_SKIP() << "external test data not found under " << root;
  const TriSurface body = read_surface((root / "L4_body.obj").string(), 1000.0, UpAxis::z);
  const TriSurface whole =
      read_surface((root / "L4_Schrumpfverpacken.obj").string(), 1000.0, UpAxis::z);
  EXPECT_EQ(body.V.rows(), 2356);
  EXPECT_EQ(body.F.rows(), 4078);
  const Eigen::RowVector3d lo = body.V.colwise().minCoeff(), hi = body.V.colwise().maxCoeff();
  // Measured once from the file: x (lateral) ±26.1, y (up) 48.2..80.2, z (anterior) -2.8..36.2 mm.
  EXPECT_NEAR(lo.x(), -26.14, 0.01);
  EXPECT_NEAR(hi.x(), 26.14, 0.01);
  EXPECT_NEAR(lo.y(), 48.24, 0.01);
  EXPECT_NEAR(hi.y(), 80.16, 0.01);
  EXPECT_NEAR(lo.z(), -2.82, 0.01);
  EXPECT_NEAR(hi.z(), 36.15, 0.01);
  // Sanity of size: a lumbar body about 52 mm wide, 39 mm deep, 32 mm tall (incl. endplate rims).
  EXPECT_GT(hi.x() - lo.x(), 40);
  EXPECT_LT(hi.x() - lo.x(), 60);
  // Anterior is +z: the posterior elements (spinous process) of the whole vertebra reach far to
  // -z behind the body, while the front of the whole vertebra is the front of the body.
  const double whole_min_z = whole.V.col(2).minCoeff(), whole_max_z = whole.V.col(2).maxCoeff();
  EXPECT_LT(whole_min_z, lo.z() - 30.0);
  EXPECT_NEAR(whole_max_z, hi.z(), 2.0);
  // Left-right symmetric about x = 0 (mid-sagittal plane).
  EXPECT_NEAR(body.V.col(0).mean(), 0.0, 0.5);
}
