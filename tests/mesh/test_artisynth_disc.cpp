// The peer model's hexahedral discs (artisynth_disc.hpp): the hexahedron split is conforming and
// exact in volume on a synthetic block with scrambled node numbers, and the real L4-L5 disc of
// the shared test data (skipped when absent) reads as a valid, closed, labelled disc whose
// fibres are found.
#include "spinesim/mesh/artisynth_disc.hpp"

#include "spinesim/mesh/io.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <set>

using namespace spinesim;
using namespace spinesim::mesh;
namespace fs = std::filesystem;

namespace {

/// Each undirected boundary edge must bound exactly two boundary faces (a closed surface), and
/// each interior face must be shared by exactly two tets (no hanging faces).
void expect_conforming_and_closed(const TetMesh& m) {
  std::map<std::array<int, 3>, int> faces;
  static const int local[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    for (const auto& f : local) {
      std::array<int, 3> k{m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::sort(k.begin(), k.end());
      ++faces[k];
    }
  std::map<std::pair<int, int>, int> edges;
  for (const auto& [k, n] : faces) {
    ASSERT_LE(n, 2) << "a face shared by three tets";
    if (n == 1)
      for (int a = 0; a < 3; ++a) ++edges[{k[a], k[(a + 1) % 3]}];  // sorted: k[0] < k[2]
  }
  for (const auto& [e, n] : edges) {
    const int count = n + (edges.count({e.second, e.first}) ? edges.at({e.second, e.first}) : 0);
    EXPECT_EQ(count, 2) << "boundary edge " << e.first << "-" << e.second;
  }
}

/// A block of nx × ny × nz unit hexahedra (mm → written in m), node ids shuffled, as the
/// model's files: the ring AN_R1..R4 files get the block (R1) or nothing (R2-R4 empty), NP one
/// hexahedron row; O/U/A lists from the top, bottom and side faces.
fs::path write_block(int nx, int ny, int nz, unsigned seed) {
  const fs::path dir = fs::temp_directory_path() / ("artisynth_block_" + std::to_string(seed));
  fs::create_directories(dir);
  std::vector<long> ids((nx + 1) * (ny + 1) * (nz + 1));
  std::iota(ids.begin(), ids.end(), 1);
  std::shuffle(ids.begin(), ids.end(), std::mt19937(seed));
  const auto id = [&](int i, int j, int k) { return ids[(k * (ny + 1) + j) * (nx + 1) + i]; };
  std::ofstream node(dir / "L45_AN_R1.node"), elem(dir / "L45_AN_R1.elem");
  std::ofstream up(dir / "L45_AN_R1O.txt"), down(dir / "L45_AN_R1U.txt"), side(dir / "L45_AN_R4A.txt");
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        // File frame: z superior (metres).
        node << id(i, j, k) << "\t" << 0.002 * i << "\t" << 0.003 * j << "\t" << 0.0025 * k << "\n";
        if (k == nz) up << id(i, j, k) << "\n";
        if (k == 0) down << id(i, j, k) << "\n";
        if (i == 0 && k > 0 && k < nz) side << id(i, j, k) << "\n";
      }
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        elem << id(i, j, k) << " " << id(i + 1, j, k) << " " << id(i + 1, j + 1, k) << " "
             << id(i, j + 1, k) << " " << id(i, j, k + 1) << " " << id(i + 1, j, k + 1) << " "
             << id(i + 1, j + 1, k + 1) << " " << id(i, j + 1, k + 1) << " 1 1 1 1 0 1\n";
  for (const char* part : {"AN_R2", "AN_R3", "AN_R4", "NP"}) {
    std::ofstream(dir / ("L45_" + std::string(part) + ".node"));
    std::ofstream(dir / ("L45_" + std::string(part) + ".elem"));
    std::ofstream(dir / ("L45_" + std::string(part) + "O.txt"));
    std::ofstream(dir / ("L45_" + std::string(part) + "U.txt"));
  }
  return dir;
}

TEST(ArtisynthDisc, HexSplitIsConformingAndExactWithAnyNumbering) {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    const fs::path dir = write_block(3, 2, 2, seed);
    const TetMesh m = read_artisynth_disc(dir.string(), "L4-L5");
    EXPECT_EQ(m.num_tets(), 6 * 3 * 2 * 2);
    EXPECT_EQ(m.num_vertices(), 4 * 3 * 3);
    // Volume 6 × 6 × 5 mm (2, 3, 2.5 mm cells), every tet positive (validate ran in the reader).
    EXPECT_NEAR(mesh_volume(m), 6.0 * 6.0 * 5.0, 1e-9);
    for (Eigen::Index t = 0; t < m.num_tets(); ++t) EXPECT_GT(tet_volume(m, t), 0);
    expect_conforming_and_closed(m);
    // z superior in the file: the endplates face ±y in our frame, and the frame's axis is y.
    EXPECT_NEAR(m.frame.axes.col(1).y(), 1.0, 1e-12);
    EXPECT_EQ((m.surface.array() == 2).count(), 4 * 3);
    EXPECT_EQ((m.surface.array() == 1).count(), 4 * 3);
    fs::remove_all(dir);
  }
}

TEST(ArtisynthDisc, BadInputIsRefused) {
  EXPECT_THROW(artisynth_level_prefix("L6-L7"), std::invalid_argument);
  EXPECT_EQ(artisynth_level_prefix("L5-S1"), "L51");
  EXPECT_THROW(read_artisynth_disc("/nonexistent", "L4-L5"), std::invalid_argument);
  const fs::path dir = write_block(1, 1, 1, 9);
  std::ofstream(dir / "L45_NP.elem") << "1 2 3 4 5 6 7 999 1 1 1 1 0 1\n";  // an unknown node
  EXPECT_THROW(read_artisynth_disc(dir.string(), "L4-L5"), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(ArtisynthDisc, PeerL4L5IsAClosedLabelledDiscWithItsFibres) {
  const std::string dir = std::string(SPINESIM_TESTDATA_DIR) + "/artisynth-lss/fe-discs";
  if (!fs::exists(dir + "/L45_NP.node")) GTEST_SKIP() << "shared test data absent";
  const TetMesh m = read_artisynth_disc(dir, "L4-L5");
  EXPECT_EQ(m.num_vertices(), 2149);  // the count the data's README gives
  EXPECT_EQ(m.num_tets() % 6, 0);
  expect_conforming_and_closed(m);
  EXPECT_GT((m.region.array() == 2).count(), 0);
  EXPECT_GT((m.surface.array() == 1).count(), 100);
  EXPECT_GT((m.surface.array() == 2).count(), 100);
  EXPECT_NEAR(m.frame.axes.determinant(), 1.0, 1e-12);
  // A lumbar disc: 15-30 cm^3, its axis near our y (the model's z).
  EXPECT_GT(mesh_volume(m), 15000);
  EXPECT_LT(mesh_volume(m), 30000);
  EXPECT_GT(m.frame.axes.col(1).y(), 0.8);
  const PeerFibreField f = peer_fibre_field(m, read_artisynth_fibres(dir, "L4-L5"));
  Eigen::Index with_two = 0;
  for (Eigen::Index t = 0; t < m.num_tets(); ++t)
    if (m.region(t) == 1) {
      EXPECT_NEAR(f.direction_1.row(t).norm(), 1.0, 1e-12);
      with_two += f.direction_2.row(t).norm() > 0.5;
    } else {
      EXPECT_EQ(f.direction_1.row(t).norm(), 0.0);
    }
  EXPECT_EQ(with_two, (m.region.array() == 1).count());  // both families everywhere
}

}  // namespace
