// Thesis findings the model does NOT reproduce (measured, not loosened): a stable equilibrium
// under a backward force on T1, and the Wilke crate with disc joints (spine/README.md,
// "Limitations we keep"). Label `targets`: left out of the default and sanitizer runs
// so main stays green; run them with `ctest --test-dir build/release -L targets`.
#include "spine_cli_fixtures.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

using nlohmann::json;
using namespace spinesim::test_cli;

// Thesis 3.3.4: with the lumbar muscles in, the spine reached equilibrium under backward forces.
// Ours does, but under 300 N backward on T1 that equilibrium is not stable (negative tangent
// stiffness in lumbar lateral bending): minimal-effort recruitment does not co-contract.
TEST(SpineTargets, BackwardForceOnT1GivesAStableEquilibrium) {
  const json j = solve_json("--force T1:0,0,-300");
  ASSERT_FALSE(j.empty());
  EXPECT_GT(j["stability"]["min_stiffness_nmm_per_rad"].get<double>(), 0.0)
      << j["stability"]["softest_mode"];
}

// With the discs as joint springs (--disc-joints, docs/disc-model.md) the Wilke crate case puts
// 3819 N (FEM fibre-reinforced discs), 3830 N (tuned MSS discs) or 3911 N (nonlinear
// fibre-reinforced discs) on L4-L5, above the 3240 N ± 15 % window (the thesis's F.4 joints:
// 3525 N): the discs carry less of the extension moment than F.4's stiffer extension springs, so
// the muscles pull harder. With the nonlinear discs McGill's L5-S1 case also ends 0.2 % above
// its window (4699 N).
TEST(SpineTargets, WilkeCrateInsideItsWindowWithDiscJoints) {
  for (const char* joints : {"fibre-reinforced", "tuned-mss", "fibre-reinforced-nonlinear"}) {
    const json& j = study(std::string("validation --disc-joints ") + joints);
    ASSERT_FALSE(j.empty()) << joints;
    EXPECT_TRUE(j["mcgill"]["pass"].get<bool>()) << joints << ": " << j["mcgill"]["axial_n"];
    EXPECT_TRUE(j["wilke"]["pass"].get<bool>())
        << joints << ": L4-L5 axial " << j["wilke"]["axial_n"] << " N";
  }
}
