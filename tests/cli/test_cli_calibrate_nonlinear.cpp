// `spinesim calibrate --nonlinear`: the network fitted to the nonlinear FEM disc at several load
// levels. The JSON report has every (case, level) in its set, the file is what was printed and
// carries the fibre elements, `mss --params` loads it, and the linear calibration's options are
// refused beside --nonlinear (and the nonlinear ones without it), one line, no file.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using namespace spinesim::test_cli;

std::string quoted(const std::string& path) { return "'" + path + "'"; }

/// The structured L4-L5 disc, meshed once per process.
const std::string& structured_disc() {
  static const std::string path = [] {
    const std::string p = tmp("nonlinear-disc.vtu");
    const CliRun r = run_spinesim("mesh disc --level L4-L5 --structured --out " + quoted(p));
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

const std::string kSmall =
    " --material fibre-reinforced --nonlinear --train compression,flexion --holdout torsion "
    "--terms thesis --load-levels 0.1,1";

}  // namespace

TEST(CalibrateCliNonlinear, ReportsEveryCaseAndLevelAndWritesTheFibreNetwork) {
  const std::string out = tmp("tuned-nonlinear.json");
  const CliRun r = run_spinesim("calibrate --mesh " + quoted(structured_disc()) + kSmall +
                                " --out " + quoted(out) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << r.out;
  EXPECT_EQ(j.at("out"), out);
  EXPECT_EQ(j.at("fem_order"), 1);  // --order's default under --nonlinear
  EXPECT_TRUE(j.at("terms").at("fibre_springs").get<bool>());
  EXPECT_TRUE(j.at("terms").at("isochoric_fibres").get<bool>());
  EXPECT_TRUE(j.at("scales").contains("fibre"));
  const json& rep = j.at("report");
  EXPECT_EQ(rep.at("reference"), "nonlinear FEM");
  EXPECT_EQ(rep.at("load_levels"), json::array({0.1, 1.0}));
  ASSERT_EQ(rep.at("train").size(), 4u);
  ASSERT_EQ(rep.at("holdout").size(), 2u);
  for (const char* set : {"train", "holdout"})
    for (const auto& row : rep.at(set)) {
      for (const char* key : {"untuned_error", "tuned_error", "untuned_reaction_error",
                              "tuned_reaction_error", "fem_plate_rotation_deg"})
        EXPECT_GE(row.at(key).get<double>(), 0.0) << set << " " << key;
      EXPECT_TRUE(row.at("converged").get<bool>());
    }
  // The file is what was printed, minus where it came from and went.
  json printed = j;
  printed.erase("out");
  printed.erase("mesh_file");
  EXPECT_EQ(json::parse(slurp(out)), printed);
  // The MSS verb builds the tuned network from it.
  const CliRun m = run_spinesim("mss --mesh " + quoted(structured_disc()) +
                                " --material fibre-reinforced --params " + quoted(out) +
                                " --case compression --json");
  EXPECT_EQ(m.status, 0) << m.err;
}

TEST(CalibrateCliNonlinear, RefusesTheOtherProtocolsOptions) {
  const std::string out = tmp("tuned-nonlinear-refused.json");
  const std::string base = "calibrate --mesh " + quoted(structured_disc()) + " --out " +
                           quoted(out) + " --material fibre-reinforced";
  for (const char* linear_only : {" --per-spring", " --check-load-scale 0.5", " --no-check",
                                  " --reaction-weight 2", " --regularisation 0"}) {
    const CliRun r = run_spinesim(base + " --nonlinear" + linear_only);
    expect_refused(r, "not to --nonlinear");
    EXPECT_FALSE(fs::exists(out)) << linear_only;
  }
  expect_refused(run_spinesim(base + " --load-levels 0.5"), "--load-levels goes with --nonlinear");
  expect_refused(run_spinesim(base + " --fibre-stretch spring"),
                 "--fibre-stretch goes with --nonlinear");
  expect_refused(run_spinesim(base + " --nonlinear --load-levels 0,1"), "load levels");
  expect_refused(run_spinesim(base + " --nonlinear --load-levels 3"), "load levels");
  expect_refused(run_spinesim(base + " --nonlinear --fibre-stretch length"), "--fibre-stretch");
  EXPECT_FALSE(fs::exists(out));
}
