// `spinesim study rib-cage` and `spine solve --rib-cage`: the study's JSON contract, the order its
// cases must come in (a stiffer part never gives a more mobile thorax, removing a part never
// stiffens it), the in-vitro rows it compares against, the scenes with and without the cage, and
// its refusals. The study takes a fraction of a second.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

using nlohmann::json;
using namespace spinesim::test_cli;

namespace {

const char* const kDirections[] = {"flexion_extension", "lateral_bending", "axial_rotation"};

const json& rib_case(const std::string& name) {
  for (const auto& c : study("rib-cage")["cases"])
    if (c["case"] == name) return c;
  ADD_FAILURE() << "case " << name << " missing";
  static const json none;
  return none;
}

double rom(const json& c, const char* direction) { return c["rom_deg"][direction].get<double>(); }

}  // namespace

TEST(RibCageStudy, EveryCaseAndBothInVitroStudiesAreReported) {
  const json& s = study("rib-cage");
  ASSERT_FALSE(s.empty());
  EXPECT_EQ(s["moment_nm"], 2.0);
  EXPECT_EQ(s["cases"].size(), 7u);
  ASSERT_EQ(s["in_vitro"].size(), 2u);
  EXPECT_NE(s["in_vitro"][0]["study"].get<std::string>().find("Liebsch"), std::string::npos);
  EXPECT_NE(s["in_vitro"][1]["study"].get<std::string>().find("Mannen"), std::string::npos);
  for (const auto& v : s["in_vitro"])
    for (const char* d : kDirections) EXPECT_GT(v["growth_when_removed_pct"][d], 20.0) << d;
  for (const char* d : kDirections)
    EXPECT_DOUBLE_EQ(rib_case("no cage")["growth_when_removed_pct"][d].get<double>(), 0.0);
  EXPECT_EQ(s["scenes"].size(), 2u);
  EXPECT_EQ(s["subject"]["height_m"], 1.778);
}

// Growth = ROM(no cage)/ROM(case) − 1 follows from the ROMs it is printed beside.
TEST(RibCageStudy, GrowthIsTheRatioOfTheRangesOfMotion) {
  const json& bare = rib_case("no cage");
  for (const auto& c : study("rib-cage")["cases"])
    for (const char* d : kDirections)
      EXPECT_NEAR(c["growth_when_removed_pct"][d].get<double>(),
                  100 * (rom(bare, d) / rom(c, d) - 1), 1e-9)
          << c["case"] << " " << d;
}

// Each part only adds stiffness: the ribs on their heads stiffen the bare spine, the cartilage
// stiffens it further, and a stiffer cartilage or costovertebral joint never loosens it.
TEST(RibCageStudy, StifferPartsNeverLoosenTheThorax) {
  const char* const chain[][2] = {
      {"no cage", "ribs on their heads (no cartilage)"},
      {"ribs on their heads (no cartilage)", "whole cage, cartilage x0.25"},
      {"whole cage, cartilage x0.25", "whole cage"},
      {"whole cage", "whole cage, cartilage x4"},
      {"whole cage", "whole cage, costovertebral x4"},
      {"whole cage, cartilage x4", "whole cage, both x4"},
      {"whole cage, costovertebral x4", "whole cage, both x4"}};
  for (const auto& [looser, stiffer] : chain)
    for (const char* d : kDirections)
      EXPECT_LT(rom(rib_case(stiffer), d), rom(rib_case(looser), d))
          << stiffer << " vs " << looser << ", " << d;
}

// In the whole, loaded spine the cage bends the thorax less under gravity and a forward push.
TEST(RibCageStudy, TheCageBendsTheLoadedThoraxLess) {
  for (const auto& sc : study("rib-cage")["scenes"]) {
    const double without = sc["thoracic_flexion_deg"]["without"],
                 with = sc["thoracic_flexion_deg"]["with"];
    EXPECT_GT(without, 0) << sc["scene"];
    EXPECT_LT(with, without) << sc["scene"];
    EXPECT_GT(sc["l4l5_axial_n"]["with"].get<double>(), 0) << sc["scene"];
  }
}

TEST(RibCageStudy, TextNamesTheSourcesAndTheBody) {
  const CliRun r = run_spinesim("study rib-cage --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s :
       {"Liebsch", "Mannen", "Lebschy", "whole cage", "T1-T12 flexion", "Body: male"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
}

TEST(RibCageStudy, RefusesAMomentOutOfRange) {
  expect_refused(run_spinesim("study rib-cage --moment 0"), "moment");
  expect_refused(run_spinesim("study rib-cage --moment 50"), "moment");
  expect_refused(run_spinesim("study rib-cage --moment nan"), "moment");
}

TEST(RibCageSolve, TheOptionIsReportedAndStiffensTheThorax) {
  const json bare = solve_json("--force T1:0,0,100");
  const json caged = solve_json("--force T1:0,0,100 --rib-cage");
  ASSERT_FALSE(bare.empty() || caged.empty());
  EXPECT_FALSE(bare["options"]["rib_cage"].get<bool>());
  EXPECT_TRUE(caged["options"]["rib_cage"].get<bool>());
  const auto flexion = [](const json& j) {
    return j["vertebrae"][0]["rotation_deg"][0].get<double>() -
           j["vertebrae"][11]["rotation_deg"][0].get<double>();
  };
  EXPECT_EQ(caged["vertebrae"][11]["name"], "T12");
  EXPECT_GT(flexion(caged), 0);
  EXPECT_LT(flexion(caged), flexion(bare));
}

// The haptic scene: a scripted drag of T1 on the rib-caged multirate spine hooks and solves
// without a failure; the database spine must be the rib-caged one, and the ribs need the spine.
TEST(RibCageHaptics, TheMultirateSpineCarriesTheCageAndTheDatabaseMustMatch) {
  const std::string script = std::string(SPINESIM_DATA_DIR) + "/haptics/drag_t1_lateral.csv";
  const std::string rec = tmp("caged-drag.csv");
  const CliRun r = run_spinesim(
      "haptics run --scene spine --triangles 1500 --spine multirate --rib-cage --script '" +
      script + "' --duration 2 --no-realtime --json --record '" + rec + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const json c = json::parse(r.out)["compliant_stage"];
  EXPECT_TRUE(c["rib_cage"].get<bool>());
  EXPECT_GT(c["hooked_ticks"].get<int>(), 500);  // the button is held from 1.0 s
  EXPECT_GT(c["worker_solves"].get<int>(), 2);
  EXPECT_EQ(c["worker_failures"].get<int>(), 0);
  // T1 pulled sideways moves the lumbar vertebrae far less than T1 (a static solve: L4 0.1 % of
  // T1). Once the left ribs 1-5 were named as L1-L5 and their poses moved the lumbar vertebrae
  // of the scene and the recording by more than T1 moved.
  const double t1 = max_abs(csv_column(rec, "T1_tx_mm"));
  EXPECT_GT(t1, 2);
  for (const char* v : {"L1_tx_mm", "L2_tx_mm", "L3_tx_mm", "L4_tx_mm", "L5_tx_mm"})
    EXPECT_LT(max_abs(csv_column(rec, v)), 0.25 * t1) << v;

  expect_refused(run_spinesim("haptics run --duration 1 --scene plane --rib-cage"),
                 "--scene spine");
  expect_refused(run_spinesim("haptics run --duration 1 --scene spine --spine database --rib-cage"),
                 "rib cage");
  expect_refused(run_spinesim("spine database --check --rib-cage"), "--check");
}
