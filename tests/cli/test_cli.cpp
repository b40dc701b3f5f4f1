// The `spinesim` command-line contract (docs/cli.md): JSON fields, units,
// sign conventions, and bad input -> one line on stderr, non-zero exit, no output file.
#include "cli_runner.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using spinesim::mesh::TetMesh;

namespace {

using namespace spinesim::test_cli;

/// A coarse L4-L5 disc made once for the whole suite.
class CliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    disc_ = tmp("cli-disc.vtu");
    const CliRun r =
        run_spinesim("mesh disc --level L4-L5 --cell-size 3 --json --out '" + disc_ + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    mesh_json_ = nlohmann::json::parse(r.out);
  }
  static std::string disc_;
  static nlohmann::json mesh_json_;
};
std::string CliTest::disc_;
nlohmann::json CliTest::mesh_json_;

}  // namespace

TEST(Cli, HelpOnEveryVerb) {
  for (const char* verb :
       {"", "mesh", "mesh disc", "fem", "demo", "bench", "bench mesh", "bench fem"}) {
    const CliRun r = run_spinesim(std::string(verb) + " --help");
    EXPECT_EQ(r.status, 0) << verb;
    EXPECT_NE(r.out.find("--"), std::string::npos) << verb;
  }
}

TEST_F(CliTest, MeshJsonHasQualityFields) {
  for (const char* key :
       {"nodes", "tets", "min_dihedral_deg", "max_dihedral_deg", "max_radius_edge_ratio",
        "volume_mm3", "exact_volume_mm3", "volume_error", "level"})
    EXPECT_TRUE(mesh_json_.contains(key)) << key;
  EXPECT_GT(mesh_json_["tets"].get<int>(), 100);
  EXPECT_LT(std::abs(mesh_json_["volume_error"].get<double>()), 0.05);
  EXPECT_TRUE(fs::exists(disc_));
}

TEST_F(CliTest, FemCompressionGivesPositiveFyAndSymmetricStiffness) {
  const std::string out = tmp("cli-fem.vtu");
  const CliRun r = run_spinesim("fem --mesh '" + disc_ +
                                "' --order 1 --motion 0,-0.1,0,0,0,0 --json --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key :
       {"nodes", "tets", "plate_center", "plate_motion", "reaction_wrench", "stiffness_6x6"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["plate_motion"].size(), 6u);
  EXPECT_EQ(j["reaction_wrench"].size(), 6u);
  EXPECT_NEAR(j["plate_motion"][1].get<double>(), -0.1, 1e-12);
  EXPECT_GT(j["reaction_wrench"][1].get<double>(), 0.0);  // compression pushes the plate up
  const auto k = j["stiffness_6x6"];
  ASSERT_EQ(k.size(), 6u);
  // Translational block is symmetric in any units.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(k[a][b].get<double>(), k[b][a].get<double>(),
                  1e-6 * std::abs(k[1][1].get<double>()));
  // Reaction = -K q for the prescribed motion.
  EXPECT_NEAR(j["reaction_wrench"][1].get<double>(), 0.1 * k[1][1].get<double>(),
              1e-6 * std::abs(k[1][1].get<double>()));
  // The result file holds the displacement field, readable back.
  std::vector<spinesim::mesh::DataArray> arrays;
  const TetMesh m = spinesim::mesh::read_vtu(out, &arrays);
  EXPECT_EQ(m.num_tets(), j["tets"].get<long>());
  bool found = false;
  for (const auto& a : arrays) found |= a.name == "displacement" && a.values.cols() == 3;
  EXPECT_TRUE(found);
}

TEST_F(CliTest, FemWrenchIsBalancedByReaction) {
  const CliRun r =
      run_spinesim("fem --mesh '" + disc_ + "' --order 1 --wrench 10,-500,20,300,-200,100 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double w[6] = {10, -500, 20, 300, -200, 100};
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(j["reaction_wrench"][i].get<double>(), -w[i], 1e-6 * 500) << i;
}

TEST_F(CliTest, BadLoadsAreRefusedWithoutOutput) {
  const std::string out = tmp("cli-bad.vtu");
  expect_refused(
      run_spinesim("fem --mesh '" + disc_ + "' --wrench 0,nan,0,0,0,0 --out '" + out + "'"),
      "not a finite number");
  expect_refused(run_spinesim("fem --mesh '" + disc_ + "' --motion 0,-0.1,0 --out '" + out + "'"),
                 "expected 6");
  expect_refused(run_spinesim("fem --mesh '" + disc_ +
                              "' --order 3 --motion 0,-0.1,0,0,0,0 --out '" + out + "'"),
                 "order");
  expect_refused(run_spinesim("fem --mesh '" + disc_ + "' --case squat --out '" + out + "'"),
                 "unknown load case");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliTest, BadMaterialsAreRefused) {
  const std::string out = tmp("cli-bad-material.vtu");
  const std::pair<const char*, const char*> cases[] = {
      {R"({"name":"zero","E_mpa":0,"nu":0.3})", "Young's modulus"},
      {R"({"name":"neg","E_mpa":-1,"nu":0.3})", "Young's modulus"},
      {R"({"name":"half","E_mpa":1,"nu":0.5})", "Poisson"},
      {R"({"name":"minus1","E_mpa":1,"nu":-1})", "Poisson"},
      {R"({"name":"rubber51","E_mpa":30,"G_mpa":0.6})", "imply nu"}};
  for (const auto& [text, needle] : cases) {
    const std::string path = tmp("material.json");
    std::ofstream(path) << text;
    expect_refused(run_spinesim("fem --mesh '" + disc_ + "' --material '" + path +
                                "' --motion 0,-0.1,0,0,0,0 --out '" + out + "'"),
                   needle);
  }
  expect_refused(
      run_spinesim("fem --mesh '" + disc_ + "' --material unobtainium --motion 0,-0.1,0,0,0,0"),
      "unknown material");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliTest, BadMeshesAreRefused) {
  const std::string out = tmp("cli-bad-mesh-out.vtu");
  const std::string motion = " --motion 0,-0.1,0,0,0,0 --out '" + out + "'";
  expect_refused(run_spinesim("fem --mesh /nonexistent/disc.vtu" + motion), "disc.vtu");

  const std::string corrupt = tmp("corrupt.vtu");
  std::ofstream(corrupt)
      << "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=";
  expect_refused(run_spinesim("fem --mesh '" + corrupt + "'" + motion), "corrupt.vtu");

  TetMesh m = spinesim::mesh::read_vtu(disc_);
  TetMesh unlabeled = m;
  unlabeled.surface.setZero();
  const std::string no_labels = tmp("no-labels.vtu");
  spinesim::mesh::write_vtu(no_labels, unlabeled);
  expect_refused(run_spinesim("fem --mesh '" + no_labels + "'" + motion), "endplate");

  TetMesh inverted = m;
  std::swap(inverted.T(0, 0), inverted.T(0, 1));
  const std::string inv = tmp("inverted.vtu");
  spinesim::mesh::write_vtu(inv, inverted);
  expect_refused(run_spinesim("fem --mesh '" + inv + "'" + motion), "inverted");

  TetMesh flat = m;
  flat.V.row(flat.T(0, 3)) = flat.V.row(flat.T(0, 0));  // collapse a tet to zero volume
  const std::string zero = tmp("zero-volume.vtu");
  spinesim::mesh::write_vtu(zero, flat);
  expect_refused(run_spinesim("fem --mesh '" + zero + "'" + motion), "volume");
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, BadMeshRequestsAreRefused) {
  const std::string out = tmp("cli-no-mesh.vtu");
  expect_refused(run_spinesim("mesh disc --level L9-L10 --out '" + out + "'"), "L9-L10");
  expect_refused(run_spinesim("mesh disc --level L4-L5 --cell-size -1 --out '" + out + "'"),
                 "cell-size");
  const std::string empty = tmp("empty.obj");
  std::ofstream(empty) << "# nothing here\n";
  expect_refused(run_spinesim("mesh disc --inferior '" + empty + "' --superior '" + empty +
                              "' --out '" + out + "'"),
                 "empty.obj");
  expect_refused(
      run_spinesim("mesh disc --level L4-L5 --inferior a.obj --superior b.obj --out '" + out + "'"),
      "either");
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, VertebraeThatDoNotFaceEachOtherAreRefused) {
  const fs::path dir = fs::path(SPINESIM_TESTDATA_DIR) / "artisynth-lss";
  if (!fs::exists(dir / "L4_body.obj")) GTEST_SKIP() << "testdata absent: " << dir;
  const std::string out = tmp("cli-swapped.vtu");
  // Inferior and superior swapped: L4 lies above L5, so they face away from each other.
  expect_refused(
      run_spinesim("mesh disc --inferior '" + (dir / "L4_body.obj").string() + "' --superior '" +
                   (dir / "L5_body.obj").string() + "' --units m --up z --out '" + out + "'"),
      "face");
  EXPECT_FALSE(fs::exists(out));
}
