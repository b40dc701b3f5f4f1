// `spinesim export --format abaqus`: the deck CalculiX runs as it is gives our `fem` answer
// (the element-by-element comparison is tests/fem/test_abaqus_deck_calculix_reference.cpp);
// `--format febio` writes the plate motion our `fem` finds under a case (the file's structure is
// tests/fem/test_febio_deck.cpp); bad requests are one line and write nothing.
#include "cli_runner.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

namespace spinesim::test_cli {
namespace {

const std::string& structured_disc() {
  static const std::string path = [] {
    const std::string p = tmp("export_disc.vtu");
    const CliRun r = run_spinesim("mesh disc --level L4-L5 --structured --quiet --out '" + p + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

/// The largest displacement of the NALL block of a CalculiX .dat file.
double max_displacement(const std::string& dat) {
  const std::size_t at = dat.rfind(" displacements (vx,vy,vz) for set NALL");
  EXPECT_NE(at, std::string::npos);
  std::istringstream in(dat.substr(at));
  std::string line;
  std::getline(in, line);
  double big = 0;
  for (bool started = false; std::getline(in, line);) {
    std::istringstream w(line);
    long id = 0;
    double x = 0, y = 0, z = 0;
    if (!(w >> id >> x >> y >> z)) {
      if (started) break;
      continue;
    }
    started = true;
    big = std::max(big, std::sqrt(x * x + y * y + z * z));
  }
  return big;
}

}  // namespace

TEST(CliExport, CalculixRunsTheAbaqusDeckToOurAnswer) {
  const std::string dir = tmp("export_case"), deck = dir + "/flexion.inp";
  std::filesystem::create_directories(dir);
  const std::string common =
      "--mesh '" + structured_disc() + "' --material fibre-reinforced --case flexion --json";
  const CliRun e = run_spinesim("export " + common + " --out '" + deck + "'");
  ASSERT_EQ(e.status, 0) << e.err;
  const auto j = nlohmann::json::parse(e.out);
  EXPECT_EQ(j["element"], "C3D10");
  EXPECT_EQ(j["load"], "wrench");
  const CliRun f = run_spinesim("fem " + common);
  ASSERT_EQ(f.status, 0) << f.err;
  const double ours = nlohmann::json::parse(f.out)["max_displacement_mm"].get<double>();
  if (!std::filesystem::exists("/usr/bin/ccx")) GTEST_SKIP() << "CalculiX (calculix-ccx) not installed";
  ASSERT_EQ(std::system(("cd '" + dir + "' && OMP_NUM_THREADS=1 /usr/bin/ccx -i flexion > ccx.log 2>&1").c_str()), 0)
      << slurp(dir + "/ccx.log");
  EXPECT_NEAR(max_displacement(slurp(dir + "/flexion.dat")), ours, 1e-5 * ours);
}

TEST(CliExport, FebioFileCarriesThePlateMotionOfOurFemUnderTheCase) {
  const std::string out = tmp("export_flexion.feb");
  const std::string common =
      "--mesh '" + structured_disc() + "' --material fibre-reinforced --case flexion --json";
  const CliRun e = run_spinesim("export --format febio " + common + " --out '" + out + "'");
  ASSERT_EQ(e.status, 0) << e.err;
  const auto j = nlohmann::json::parse(e.out);
  EXPECT_EQ(j["element"], "tet10");
  EXPECT_EQ(j["load"], "motion");
  const CliRun f = run_spinesim("fem " + common);
  ASSERT_EQ(f.status, 0) << f.err;
  const auto fem = nlohmann::json::parse(f.out);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(j["load_value"][k].get<double>(), fem["plate_motion"][k].get<double>(), 1e-12);
    // The case's wrench, which the plate's reaction balances.
    EXPECT_NEAR(j["motion_solved_for_wrench"][k].get<double>(),
                -fem["reaction_wrench"][k].get<double>(), 1e-6);
  }
  const std::string text = slurp(out);
  EXPECT_NE(text.find("<febio_spec version=\"4.0\">"), std::string::npos);
  EXPECT_NE(text.find("type=\"orthotropic elastic\""), std::string::npos);
}

TEST(CliExport, BadRequestsAreOneLineAndWriteNothing) {
  const std::string out = tmp("export_bad.inp");
  std::filesystem::remove(out);
  const std::string mesh = "--mesh '" + structured_disc() + "' --out '" + out + "'";
  expect_refused(run_spinesim("export " + mesh + " --format ansys"), "ansys");
  expect_refused(run_spinesim("export " + mesh + " --format febio --order 3"), "order");
  expect_refused(run_spinesim("export " + mesh + " --case flexion --motion 0,0,0,0,0,0"),
                 "at most one");
  expect_refused(run_spinesim("export " + mesh + " --order 3"), "order");
  expect_refused(run_spinesim("export " + mesh + " --case bending"), "bending");
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace spinesim::test_cli
