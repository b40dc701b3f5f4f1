// Medit .mesh writer: counts, 1-based indices, boundary triangles (outward, labelled), exact
// coordinates, an independent reader (meshio), and refusal of bad input without leaving a file.
#include "spinesim/mesh/io.hpp"

#include "io_fixtures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using namespace spinesim::mesh;

namespace {

TetMesh cube_mesh() { return test::kuhn_cube_mesh(); }

std::string tmp_dir(const std::string& name) { return test::fresh_tmp_dir("io_medit_", name); }

/// The sections of a Medit ASCII file as rows of numbers.
struct MeditFile {
  int version = 0, dimension = 0;
  std::map<std::string, std::vector<std::vector<double>>> sections;
  bool ended = false;
};

MeditFile parse_medit(const std::string& path) {
  MeditFile f;
  std::ifstream is(path);
  std::string word;
  const std::map<std::string, int> width = {{"Vertices", 4}, {"Tetrahedra", 5}, {"Triangles", 4}};
  while (is >> word) {
    if (word == "MeshVersionFormatted")
      is >> f.version;
    else if (word == "Dimension")
      is >> f.dimension;
    else if (word == "End")
      f.ended = true;
    else if (width.count(word)) {
      std::size_t n;
      is >> n;
      auto& rows = f.sections[word];
      rows.assign(n, std::vector<double>(std::size_t(width.at(word))));
      for (auto& r : rows)
        for (double& x : r) is >> x;
    } else {
      ADD_FAILURE() << "unexpected keyword " << word;
      break;
    }
  }
  return f;
}

}  // namespace

TEST(IoMedit, CountsIndicesAndExactCoordinates) {
  const std::string path = tmp_dir("counts") + "/cube.mesh";
  const TetMesh m = cube_mesh();
  write_medit(path, m);
  const MeditFile f = parse_medit(path);
  EXPECT_EQ(f.version, 2);
  EXPECT_EQ(f.dimension, 3);
  EXPECT_TRUE(f.ended);
  const auto& V = f.sections.at("Vertices");
  const auto& T = f.sections.at("Tetrahedra");
  ASSERT_EQ(V.size(), 8u);
  ASSERT_EQ(T.size(), 6u);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_EQ(V[i][j], m.V(i, j));  // shortest exact decimal form
    EXPECT_EQ(V[i][3], m.surface(i));
  }
  for (int t = 0; t < 6; ++t) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(T[t][k], m.T(t, k) + 1);  // 1-based
    EXPECT_EQ(T[t][4], m.region(t));
  }
}

TEST(IoMedit, BoundaryTrianglesAreOutwardAndLabelled) {
  const std::string path = tmp_dir("boundary") + "/cube.mesh";
  const TetMesh m = cube_mesh();
  write_medit(path, m);
  const MeditFile file = parse_medit(path);
  const auto& F = file.sections.at("Triangles");
  ASSERT_EQ(F.size(), 12u);  // 6 cube faces × 2 triangles; the inner faces are not boundary
  const Eigen::Vector3d centre = m.V.colwise().mean();
  std::map<int, int> per_label;
  double area = 0;
  for (const auto& t : F) {
    const Eigen::Vector3d a = m.V.row(int(t[0]) - 1), b = m.V.row(int(t[1]) - 1),
                          c = m.V.row(int(t[2]) - 1);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    EXPECT_GT(n.dot((a + b + c) / 3 - centre), 0) << "triangle not outward";
    area += 0.5 * n.norm();
    ++per_label[int(t[3])];
    const double y = (a.y() + b.y() + c.y()) / 3;
    if (int(t[3]) == 1) EXPECT_DOUBLE_EQ(y, m.V.col(1).minCoeff());
    if (int(t[3]) == 2) EXPECT_DOUBLE_EQ(y, m.V.col(1).maxCoeff());
  }
  const double h = m.V.col(0).maxCoeff() - m.V.col(0).minCoeff();
  EXPECT_NEAR(area, 6 * h * h, 1e-9 * h * h);
  EXPECT_EQ(per_label[1], 2);  // inferior endplate
  EXPECT_EQ(per_label[2], 2);  // superior endplate
  EXPECT_EQ(per_label[3], 8);  // outer wall: vertices with mixed labels
}

TEST(IoMedit, UnlabelledBoundaryIsOuterWall) {
  const std::string path = tmp_dir("unlabelled") + "/cube.mesh";
  TetMesh m = cube_mesh();
  m.surface.setZero();
  write_medit(path, m);
  const MeditFile file = parse_medit(path);
  ASSERT_EQ(file.sections.at("Triangles").size(), 12u);
  for (const auto& t : file.sections.at("Triangles")) EXPECT_EQ(t[3], 3);
}

TEST(IoMedit, MeshioReadsIt) {
  if (!fs::exists("/usr/bin/python3") ||
      std::system("/usr/bin/python3 -c 'import meshio' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 with meshio not available";
  const std::string dir = tmp_dir("meshio");
  const std::string path = dir + "/cube.mesh";
  write_medit(path, cube_mesh());
  const std::string out = dir + "/out.txt";
  const std::string cmd =
      "/usr/bin/python3 -c \"import sys, meshio; m = meshio.read(sys.argv[1]); "
      "d = {c.type: len(c.data) for c in m.cells}; "
      "print(len(m.points), d.get('tetra', 0), d.get('triangle', 0), "
      "int(sum(sum(r) for r in m.cell_data['medit:ref'][:1])))\" " +
      path + " > " + out + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << std::ifstream(out).rdbuf();
  std::ifstream is(out);
  long np = -1, nt = -1, nf = -1, ref_sum = -1;
  is >> np >> nt >> nf >> ref_sum;
  EXPECT_EQ(np, 8);
  EXPECT_EQ(nt, 6);
  EXPECT_EQ(nf, 12);
  // meshio lists blocks in file order: tetrahedra first, refs 1,2,1,2,1,2.
  EXPECT_EQ(ref_sum, 9);
}

TEST(IoMedit, RefusesBadInputAndLeavesNoFile) {
  const std::string dir = tmp_dir("bad");
  const std::string path = dir + "/bad.mesh";
  TetMesh m = cube_mesh();
  m.V(4, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    write_medit(path, m);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
  m = cube_mesh();
  m.surface.resize(3);
  EXPECT_THROW(write_medit(path, m), std::invalid_argument);
  m = cube_mesh();
  m.T(2, 1) = -1;
  EXPECT_THROW(write_medit(path, m), std::invalid_argument);
  EXPECT_THROW(write_medit(path, TetMesh{}), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(dir));
  EXPECT_THROW(write_medit(dir + "/missing/folder/x.mesh", cube_mesh()), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir));
}
