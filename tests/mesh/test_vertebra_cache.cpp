// The cache of meshed vertebrae: a hit gives back exactly the surface the mesher made, anything
// that is not a whole file of the same key is meshed again, and a cache that cannot be written
// costs only time.
#include "spinesim/mesh/vertebra_cache.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace sm = spinesim::mesh;
namespace fs = std::filesystem;

namespace {

const std::string kData = SPINESIM_DATA_DIR;
constexpr int kTriangles = 300;  // coarse: the cache does not care, the sanitizer build does

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(SPINESIM_TEST_TMP) / ("vertebra-cache-" + name);
  fs::remove_all(d);
  return d;
}

std::vector<fs::path> files(const fs::path& d) {
  std::vector<fs::path> out;
  if (fs::exists(d))
    for (const auto& e : fs::directory_iterator(d)) out.push_back(e.path());
  return out;
}

void expect_same(const sm::VertebraSurface& a, const sm::VertebraSurface& b) {
  EXPECT_EQ(a.name, b.name);
  ASSERT_EQ(a.surface.V.rows(), b.surface.V.rows());
  ASSERT_EQ(a.surface.F.rows(), b.surface.F.rows());
  EXPECT_TRUE((a.surface.V.array() == b.surface.V.array()).all());  // bit for bit
  EXPECT_TRUE((a.surface.F.array() == b.surface.F.array()).all());
  EXPECT_TRUE(a.frame.origin_mm == b.frame.origin_mm);
  EXPECT_TRUE(a.frame.axes == b.frame.axes);
}

}  // namespace

TEST(VertebraCache, AHitIsTheMeshersSurfaceBitForBit) {
  const fs::path dir = fresh_dir("hit");
  const auto v = sm::parametric_vertebra("L2", kData);
  bool hit = true;
  const sm::VertebraSurface first = sm::cached_vertebra_surface(v, kTriangles, dir.string(), &hit);
  EXPECT_FALSE(hit);
  ASSERT_EQ(files(dir).size(), 1u);
  const sm::VertebraSurface second = sm::cached_vertebra_surface(v, kTriangles, dir.string(), &hit);
  EXPECT_TRUE(hit);
  expect_same(first, second);
  expect_same(first, sm::mesh_vertebra(v, kTriangles));  // the mesher is deterministic
}

TEST(VertebraCache, TheKeyFollowsEveryParameterAndTheTarget) {
  const auto v = sm::parametric_vertebra("L2", kData);
  const std::string key = sm::vertebra_cache_key(v, kTriangles);
  EXPECT_EQ(key, sm::vertebra_cache_key(v, kTriangles));
  EXPECT_NE(key, sm::vertebra_cache_key(v, kTriangles + 1));
  auto w = v;
  w.body_height_mm += 1e-9;
  EXPECT_NE(key, sm::vertebra_cache_key(w, kTriangles));
  w = v;
  w.parts.front().rounding_mm *= 1.01;
  EXPECT_NE(key, sm::vertebra_cache_key(w, kTriangles));
  w = v;
  w.frame.origin_mm.y() += 0.5;
  EXPECT_NE(key, sm::vertebra_cache_key(w, kTriangles));
  EXPECT_NE(key, sm::vertebra_cache_key(sm::parametric_vertebra("L3", kData), kTriangles));
}

TEST(VertebraCache, ABrokenOrStaleFileIsMeshedAgainAndReplaced) {
  const fs::path dir = fresh_dir("broken");
  const auto v = sm::parametric_vertebra("T8", kData);
  const sm::VertebraSurface made = sm::cached_vertebra_surface(v, kTriangles, dir.string());
  ASSERT_EQ(files(dir).size(), 1u);
  const fs::path file = files(dir).front();
  const auto size = fs::file_size(file);
  // Cut short, and with garbage appended: both are misses, and the file is whole again after.
  for (const int change : {0, 1}) {
    if (change == 0) {
      fs::resize_file(file, size / 2);
    } else {
      std::ofstream(file, std::ios::app) << "extra";
    }
    bool hit = true;
    expect_same(made, sm::cached_vertebra_surface(v, kTriangles, dir.string(), &hit));
    EXPECT_FALSE(hit) << change;
    EXPECT_EQ(fs::file_size(file), size);
  }
  // A file of the same vertebra and target from another program (another key) is removed when
  // this one is written; other vertebrae's files stay.
  std::ofstream(dir / "T8-300-0000000000000000.bin") << "old";
  std::ofstream(dir / "T80-300-0000000000000000.bin") << "not T8";
  fs::remove(file);
  sm::cached_vertebra_surface(v, kTriangles, dir.string());
  EXPECT_FALSE(fs::exists(dir / "T8-300-0000000000000000.bin"));
  EXPECT_TRUE(fs::exists(dir / "T80-300-0000000000000000.bin"));
  EXPECT_TRUE(fs::exists(file));
}

TEST(VertebraCache, NoFolderOrAnUnwritableOneOnlyMeshes) {
  const auto v = sm::parametric_vertebra("L2", kData);
  bool hit = true;
  const sm::VertebraSurface direct = sm::cached_vertebra_surface(v, kTriangles, "", &hit);
  EXPECT_FALSE(hit);
  // A regular file where the folder should be: nothing can be written, the surface still comes.
  const fs::path blocker = fresh_dir("blocked");
  std::ofstream(blocker.string()) << "a file, not a folder";
  expect_same(direct, sm::cached_vertebra_surface(v, kTriangles, blocker.string(), &hit));
  EXPECT_FALSE(hit);
  fs::remove(blocker);
}
