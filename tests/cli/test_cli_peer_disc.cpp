// `spinesim mesh import`: the peer model's L4-L5 disc (shared test data; skipped when absent)
// becomes a spinesim disc that the FEM solves, the MSS is compared on and the calibration tunes.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <filesystem>
#include <string>

namespace spinesim::test_cli {
namespace {

const std::string kDiscs = std::string(SPINESIM_TESTDATA_DIR) + "/artisynth-lss/fe-discs";

TEST(CliPeerDisc, PeerL4L5SolvesComparesAndCalibrates) {
  if (!std::filesystem::exists(kDiscs + "/L45_NP.node")) GTEST_SKIP() << "shared test data absent";
  const std::string disc = tmp("peer_l45.vtu"), tuned = tmp("peer_l45_tuned.json");
  const CliRun im = run_spinesim("mesh import --artisynth '" + kDiscs + "' --level L4-L5 --out '" +
                                 disc + "' --json");
  ASSERT_EQ(im.status, 0) << im.err;
  const auto j = nlohmann::json::parse(im.out);
  EXPECT_EQ(j["nodes"], 2149);
  // Our fibre-reinforced field laid on the peer's mesh runs within a few degrees of its fibres.
  EXPECT_LT(j["fibres"]["mean_pair_angle_to_ours_deg"].get<double>(), 10.0);

  const CliRun f = run_spinesim("fem --mesh '" + disc + "' --case flexion --json");
  ASSERT_EQ(f.status, 0) << f.err;
  const auto fem = nlohmann::json::parse(f.out);
  // The plate balances the case's 7.5 N·m about the disc's lateral axis.
  const Eigen::Vector3d lateral(j["disc_frame"]["axes"][0][0], j["disc_frame"]["axes"][1][0],
                                j["disc_frame"]["axes"][2][0]);
  const Eigen::Vector3d M(fem["reaction_wrench"][3], fem["reaction_wrench"][4],
                          fem["reaction_wrench"][5]);
  EXPECT_NEAR(M.dot(lateral), -7500.0, 1e-3);

  const CliRun c = run_spinesim("calibrate --mesh '" + disc + "' --out '" + tuned + "' --json");
  ASSERT_EQ(c.status, 0) << c.err;
  const auto compare = [&](const std::string& extra) {
    const CliRun r = run_spinesim("mss compare --mesh '" + disc + "' --load-scale 0.1 --json" + extra);
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out)["mean_displacement_error"].get<double>();
  };
  const double untuned = compare(""), calibrated = compare(" --params '" + tuned + "'");
  EXPECT_LT(calibrated, 0.5 * untuned);
}

}  // namespace
}  // namespace spinesim::test_cli
