// `spinesim mesh disc --structured`: the JSON and the VTU agree with the sweep's counts and
// labels, the resolution options take effect, bad or mixed options are refused with one line
// and no file, and the linear FEM reference runs on a structured disc (6×6 stiffness SPD).
#include "cli_runner.hpp"
#include "spinesim/fem/disc_fem.hpp"
#include "spinesim/mesh/io.hpp"
#include "spinesim/mesh/material.hpp"
#include "spinesim/mesh/tet_mesh.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <Eigen/Eigenvalues>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace spinesim;

namespace {

using namespace spinesim::test_cli;

/// A refused run: non-zero exit, one line on stderr mentioning `needle`, nothing on stdout,
/// no output file.
void expect_refused(const std::string& args, const std::string& out, const std::string& needle) {
  SCOPED_TRACE(args);
  test_cli::expect_refused(run_spinesim(args + " --out '" + out + "'"), needle);
  EXPECT_FALSE(fs::exists(out));
}

/// T7-T8 with the default structured resolution (12 sectors, 3 rings, 2 layers), made once.
class StructuredCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    disc_ = tmp("t7-t8-structured.vtu");
    const CliRun r =
        run_spinesim("mesh disc --level T7-T8 --structured --json --out '" + disc_ + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    json_ = json::parse(r.out);
  }
  static std::string disc_;
  static json json_;
};
std::string StructuredCli::disc_;
json StructuredCli::json_;

}  // namespace

TEST_F(StructuredCli, JsonReportsTheSweepCountsAndQuality) {
  // nodes (layers+1)(1 + rings·sectors), tets 3·layers·sectors·(2 rings - 1).
  EXPECT_EQ(json_["nodes"].get<int>(), 3 * 37);
  EXPECT_EQ(json_["tets"].get<int>(), 360);
  EXPECT_EQ(json_["inferior_nodes"].get<int>(), 37);
  EXPECT_EQ(json_["superior_nodes"].get<int>(), 37);
  EXPECT_EQ(json_["wall_nodes"].get<int>(), 12);
  EXPECT_EQ(json_["annulus_tets"].get<int>() + json_["nucleus_tets"].get<int>(), 360);
  EXPECT_GT(json_["min_dihedral_deg"].get<double>(), 18.5);         // worst level T4-T5: 18.9°
  EXPECT_NEAR(json_["volume_error"].get<double>(), -0.051, 0.001);  // inscribed 12-gon
  EXPECT_EQ(json_["level"], "T7-T8");
  EXPECT_EQ(json_["placement"], "spine");
  EXPECT_EQ(json_["options"]["mesher"], "structured");
  EXPECT_EQ(json_["options"]["sectors"].get<int>(), 12);
  EXPECT_EQ(json_["options"]["rings"].get<int>(), 3);
  EXPECT_EQ(json_["options"]["layers"].get<int>(), 2);
  EXPECT_FALSE(json_["options"].contains("cell_size_mm"));
}

TEST_F(StructuredCli, VtuHoldsTheSameMesh) {
  const mesh::TetMesh m = mesh::read_vtu(disc_);
  EXPECT_NO_THROW(mesh::validate(m));
  EXPECT_EQ(m.num_vertices(), json_["nodes"].get<int>());
  EXPECT_EQ(m.num_tets(), json_["tets"].get<int>());
  EXPECT_EQ((m.surface.array() == 1).count(), 37);
  EXPECT_EQ((m.surface.array() == 2).count(), 37);
  EXPECT_EQ((m.region.array() == 2).count(), json_["nucleus_tets"].get<int>());
  EXPECT_NEAR(mesh::mesh_volume(m), json_["volume_mm3"].get<double>(),
              1e-6 * json_["volume_mm3"].get<double>());
}

TEST(StructuredCliOptions, ResolutionAndPlacementTakeEffect) {
  const std::string out = tmp("l4-l5-16x4x3.vtu");
  const CliRun r = run_spinesim(
      "mesh disc --level L4-L5 --structured --sectors 16 --rings 4 --layers 3 "
      "--placement local --match-area --json --out '" +
      out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_EQ(j["nodes"].get<int>(), 4 * (1 + 4 * 16));
  EXPECT_EQ(j["tets"].get<int>(), 3 * 3 * 16 * 7);
  EXPECT_EQ(j["wall_nodes"].get<int>(), 2 * 16);
  EXPECT_LT(std::abs(j["volume_error"].get<double>()), 1e-5);  // --match-area
  EXPECT_EQ(j["options"]["match_area"], true);
  // Local placement: upright at the origin, endplates at y = ±h/2 (L4-L5: h = 11.3 mm).
  const mesh::TetMesh m = mesh::read_vtu(out);
  EXPECT_NEAR(m.V.col(1).minCoeff(), -0.5 * 11.3, 1e-3);
  EXPECT_NEAR(m.V.col(1).maxCoeff(), 0.5 * 11.3, 1e-3);
}

TEST(StructuredCliOptions, TextReportNamesTheMesher) {
  const CliRun r =
      run_spinesim("mesh disc --level T1-T2 --structured --quiet --out '" + tmp("t1-t2.vtu") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("structured disc T1-T2 (12 sectors, 3 rings, 2 layers)"), std::string::npos)
      << r.out;
  EXPECT_NE(run_spinesim("mesh disc --help").out.find("--structured"), std::string::npos);
}

TEST(StructuredCliOptions, BadOrMixedOptionsAreRefused) {
  const std::string out = tmp("refused.vtu");
  const std::string base = "mesh disc --level T7-T8 ";
  expect_refused(base + "--structured --cell-size 2", out, "--cell-size");
  expect_refused(base + "--structured --odt --seed 3", out, "--odt, --seed");
  expect_refused(base + "--structured --no-exude", out, "CGAL options");
  expect_refused(base + "--sectors 16 --layers 3", out,
                 "--sectors, --layers only apply with --structured");
  expect_refused(base + "--structured --sectors 5", out, "sectors >= 6");
  expect_refused(base + "--structured --rings 1", out, "rings >= 2");
  expect_refused(base + "--structured --layers 0", out, "layers >= 1");
  expect_refused("mesh disc --structured --inferior a.obj --superior b.obj", out, "give --level");
  expect_refused("mesh disc --structured --level T13-T14", out, "T13-T14");
}

// The linear FEM reference runs on a structured disc: K6 symmetric positive definite, and a
// compressive plate motion pushes back (F_y > 0), through the library and through the CLI.
TEST_F(StructuredCli, FemRunsOnTheStructuredDisc) {
  const mesh::TetMesh m = mesh::read_vtu(disc_);
  const auto materials = mesh::load_material("real-disc", SPINESIM_DATA_DIR);
  const fem::DiscFem solver(m, materials, 1, fem::DiscFem::default_plate_center(m));
  const auto& k6 = solver.stiffness_6x6();
  EXPECT_LT(solver.stiffness_asymmetry(), 1e-8);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(0.5 * (k6 + k6.transpose()));
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << eig.eigenvalues().transpose();

  const CliRun r =
      run_spinesim("fem --mesh '" + disc_ + "' --order 1 --motion 0,-0.1,0,0,0,0 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  EXPECT_GT(j["reaction_wrench"][1].get<double>(), 0.0);
}
