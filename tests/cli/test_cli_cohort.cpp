// `spinesim study cohort-level`: a level's parametric disc calibrated and its constants carried to
// the level's other discs. The reference's transfer error is its own fit; a scaled body's disc,
// the reference disc scaled, takes the reference's constants as well as its own fit takes them;
// every calibration beats the untuned constants; the real and peer discs join where the test data
// are; bad input is one line.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

namespace {

using namespace spinesim::test_cli;
using nlohmann::json;
namespace fs = std::filesystem;

TEST(CohortCli, AScaledBodysDiscTakesTheParametricDiscsConstants) {
  const CliRun r =
      run_spinesim("study cohort-level --level T7-T8 --cell-size 5 --bodies p5-female --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  ASSERT_EQ(j["members"].size(), 2u);  // no real or peer disc at a thoracic level
  const json& p = j["members"]["parametric"];
  const json& b = j["members"]["p5-female"];
  EXPECT_EQ(p["transfer_error"], p["own_error"]);
  for (const json* m : {&p, &b}) {
    EXPECT_TRUE((*m)["own_fit_converged"].get<bool>());
    EXPECT_LT((*m)["own_error"].get<double>(), 0.7 * (*m)["untuned_error"].get<double>());
    EXPECT_LT((*m)["transfer_error"].get<double>(), 0.7 * (*m)["untuned_error"].get<double>());
  }
  // Geometric similarity: the scaled disc's stiffness scales as the reference's, so the
  // reference's constants do nearly as well as its own fit.
  EXPECT_LT(b["transfer_error"].get<double>(), b["own_error"].get<double>() + 0.02);
  EXPECT_LT(b["volume_mm3"].get<double>(), p["volume_mm3"].get<double>());
}

TEST(CohortCli, TheRealAndThePeerDiscsJoinALumbarLevel) {
  if (!fs::is_directory(fs::path(SPINESIM_TESTDATA_DIR) / "artisynth-lss"))
    GTEST_SKIP() << "test data (artisynth-lss) absent";
  const CliRun r = run_spinesim(
      "study cohort-level --level L4-L5 --cell-size 5 --bodies none --no-own-fits --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(r.out);
  for (const char* m : {"parametric", "vertebrae", "peer"}) {
    ASSERT_TRUE(j["members"].contains(m)) << m;
    const json& e = j["members"][m];
    ASSERT_FALSE(e.contains("skipped")) << e.dump();
    EXPECT_GT(e["tets"].get<int>(), 100) << m;
    EXPECT_TRUE(e["transfer_error"].is_number()) << m;
    EXPECT_TRUE(e["own_error"].is_null() || std::string(m) == "parametric") << m;
  }
}

TEST(CohortCli, BadInputIsOneLine) {
  expect_refused(run_spinesim("study cohort-level --level L9-L10"), "L9-L10");
  expect_refused(run_spinesim("study cohort-level --cell-size 0"), "--cell-size");
  expect_refused(run_spinesim("study cohort-level --level T7-T8 --bodies nobody"), "nobody");
}

}  // namespace
