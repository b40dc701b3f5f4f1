// The cache of meshed disc levels: a hit gives back exactly the mesh the mesher made (points,
// tets, labels, frame, source), the key follows the level and every option, a damaged or foreign
// file is meshed again and replaced, and without a folder it only meshes.
#include "spinesim/mesh/disc_cache.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace sm = spinesim::mesh;
namespace fs = std::filesystem;

namespace {

const std::string kData = SPINESIM_DATA_DIR;

sm::MeshOptions coarse() {
  sm::MeshOptions o;
  o.cell_size_mm = 6.0;  // the cache does not care; the sanitizer build does
  return o;
}

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(SPINESIM_TEST_TMP) / ("disc-cache-" + name);
  fs::remove_all(d);
  return d;
}

std::vector<fs::path> files(const fs::path& d) {
  std::vector<fs::path> out;
  if (fs::exists(d))
    for (const auto& e : fs::directory_iterator(d)) out.push_back(e.path());
  return out;
}

void expect_same(const sm::TetMesh& a, const sm::TetMesh& b) {
  ASSERT_EQ(a.V.rows(), b.V.rows());
  ASSERT_EQ(a.T.rows(), b.T.rows());
  EXPECT_TRUE((a.V.array() == b.V.array()).all());  // bit for bit
  EXPECT_TRUE((a.T.array() == b.T.array()).all());
  EXPECT_TRUE((a.region.array() == b.region.array()).all());
  EXPECT_TRUE((a.surface.array() == b.surface.array()).all());
  EXPECT_TRUE(a.frame.origin_mm == b.frame.origin_mm);
  EXPECT_TRUE(a.frame.axes == b.frame.axes);
  EXPECT_EQ(a.source, b.source);
}

}  // namespace

TEST(DiscCache, AHitIsTheMeshersMeshBitForBit) {
  const fs::path dir = fresh_dir("hit");
  bool hit = true;
  const sm::TetMesh first = sm::cached_disc_level("L4-L5", coarse(), kData, dir.string(), &hit);
  EXPECT_FALSE(hit);
  ASSERT_EQ(files(dir).size(), 1u);
  const sm::TetMesh second = sm::cached_disc_level("L4-L5", coarse(), kData, dir.string(), &hit);
  EXPECT_TRUE(hit);
  expect_same(first, second);
  expect_same(first, sm::mesh_disc_level("L4-L5", coarse(), kData));  // deterministic mesher
}

TEST(DiscCache, TheKeyFollowsTheLevelAndEveryOption) {
  const std::string key = sm::disc_cache_key("L4-L5", coarse(), kData);
  EXPECT_EQ(key, sm::disc_cache_key("L4-L5", coarse(), kData));
  EXPECT_NE(key, sm::disc_cache_key("L3-L4", coarse(), kData));
  sm::MeshOptions o = coarse();
  o.cell_size_mm += 1e-9;
  EXPECT_NE(key, sm::disc_cache_key("L4-L5", o, kData));
  o = coarse();
  o.exude = false;
  EXPECT_NE(key, sm::disc_cache_key("L4-L5", o, kData));
  o = coarse();
  o.seed = 7;
  EXPECT_NE(key, sm::disc_cache_key("L4-L5", o, kData));
}

TEST(DiscCache, ADamagedOrForeignFileIsMeshedAgainAndReplaced) {
  const fs::path dir = fresh_dir("damaged");
  const sm::TetMesh made = sm::cached_disc_level("L4-L5", coarse(), kData, dir.string());
  ASSERT_EQ(files(dir).size(), 1u);
  const fs::path file = files(dir).front();
  std::ofstream(file, std::ios::trunc) << "<VTKFile>cut";
  bool hit = true;
  expect_same(made, sm::cached_disc_level("L4-L5", coarse(), kData, dir.string(), &hit));
  EXPECT_FALSE(hit);
  // Another level's file under this name (a hash collision) is not taken for this one.
  const fs::path other = fresh_dir("other");
  sm::cached_disc_level("L3-L4", coarse(), kData, other.string());
  fs::copy_file(files(other).front(), file, fs::copy_options::overwrite_existing);
  hit = true;
  expect_same(made, sm::cached_disc_level("L4-L5", coarse(), kData, dir.string(), &hit));
  EXPECT_FALSE(hit);
  EXPECT_EQ(files(dir).size(), 1u);  // replaced, not added to
}

TEST(DiscCache, WithoutAFolderItOnlyMeshes) {
  bool hit = true;
  const sm::TetMesh m = sm::cached_disc_level("L4-L5", coarse(), kData, "", &hit);
  EXPECT_FALSE(hit);
  EXPECT_GT(m.num_tets(), 100);
  // A folder that cannot be made (under a file) costs only the meshing.
  const fs::path blocker = fresh_dir("blocker");
  std::ofstream(blocker.string()) << "a file";
  EXPECT_NO_THROW(sm::cached_disc_level("L4-L5", coarse(), kData, (blocker / "sub").string()));
  fs::remove(blocker);
}
